// The absolute energy floor of modified Newton's stopping rule (docs/theory.md §6.5; paper eq. 39 made
// absolute), shared by em-galpha and em-exact's certify = energy (docs/theory/exact-energy-momentum.md §5.10).
//
// E_k = |Δu_k · r(u_{k−1})| is the energy of the k-th correction in the iteration matrix's norm, and measures the
// error of u_{k−1} (quadratically in it). u_k is accepted once
//   E_k ≤ floor                                   ("correction": u_{k−1} is within the floor, u_k better still), or
//   10 · E_k · max(E_k/E_{k−1}, E_{k−1}/E_{k−2}) ≤ floor   ("estimate": the next correction, whose energy measures
//                                                   u_k's error, is predicted below the floor from the observed
//                                                   energy contraction, the larger of the last two ratios, with
//                                                   a margin of 10),
// where floor = e_floor · E_sys, E_sys the energy the body holds (the caller's scale). One object per Newton
// solve: it keeps E_{k−1} and E_{k−2} of that solve.
#pragma once

#include <algorithm>

namespace shelldyn {

class EnergyFloorTest {
 public:
  // floor <= 0 switches the test off (accept() is then always false).
  EnergyFloorTest(double floor, bool estimate) : floor_(floor), estimate_(estimate) {}

  // Feed E_k of iteration k = 1, 2, ... in order; true = accept u_k.
  bool accept(double Ek) {
    if (floor_ <= 0.0) return false;
    if (Ek <= floor_) return true;
    if (estimate_ && e_hist_[1] > 0.0 && 10.0 * Ek * std::max(Ek / e_hist_[0], e_hist_[0] / e_hist_[1]) <= floor_)
      return true;
    e_hist_[1] = e_hist_[0];
    e_hist_[0] = Ek;
    return false;
  }

 private:
  double floor_;
  bool estimate_;
  double e_hist_[2] = {0.0, 0.0};  // E_{k−1}, E_{k−2}
};

}  // namespace shelldyn
