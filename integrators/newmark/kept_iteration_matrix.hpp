// The iteration matrix K̄ that modified Newton keeps across steps, and what a checkpoint needs to continue
// with it bitwise (docs/architecture.md "Checkpoints and resume"): the last step size (K̄ depends on h),
// the K̄ in use and the iterations done with it. Shared by em-galpha (and its family) and em-exact.
#pragma once

#include "integrators/integrator.hpp"
#include "integrators/nonlinear/newton_solver.hpp"
#include "lib/sparse_matrix.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace shelldyn {

class KeptIterationMatrix {
 public:
  // At the start of every step: a new h makes the kept K̄ useless. Steps that land on an output time differ
  // from Δt in the last bits (t_out − t); that is no reason to throw a factorization away.
  void start_step(double h, NewtonSolver& newton) {
    if (std::abs(h - last_h_) > 1e-8 * h) {
      newton.invalidate_jacobian();
      if (replay_) newton.resume_after_setup(0);  // a saved K̄ for another h is of no use
      replay_ = false;
    }
    last_h_ = h;
  }

  // In the modified solver's Jacobian callback: the first setup after restore() takes the saved K̄ (same
  // values, hence the same factorization as the uninterrupted run) instead of a new one; returns true then.
  bool replay(SparseMatrix& J) {
    if (!replay_) return false;
    J.values = kbar_;
    replay_ = false;
    return true;
  }
  // In the modified solver's Jacobian callback after a new K̄ was formed (for save()).
  void keep(const SparseMatrix& J) { kbar_ = J.values; }

  void save(IntegratorCheckpoint& c, const NewtonSolver& newton, bool modified) const {
    c.scalars["last_h"] = last_h_;
    const int since = modified ? newton.iterations_since_setup() : -1;
    c.scalars["newton_since_setup"] = since;
    if (since >= 0) c.vectors["kbar"] = Eigen::Map<const Eigen::VectorXd>(kbar_.data(), static_cast<Index>(kbar_.size()));
  }

  // `who` names the integrator in the error; `nnz` is the size K̄ must have (the system's pattern).
  void restore(const IntegratorCheckpoint& c, NewtonSolver& newton, bool modified, Index nnz, const std::string& who) {
    last_h_ = c.scalar("last_h");
    const int since = static_cast<int>(c.scalar("newton_since_setup"));
    replay_ = false;
    if (modified && since >= 0) {
      const Eigen::VectorXd& k = c.vector("kbar");
      if (k.size() != nnz) throw std::runtime_error(who + ": checkpoint K̄ has the wrong size");
      kbar_.assign(k.data(), k.data() + k.size());
      replay_ = true;
      newton.resume_after_setup(since);
    }
  }

 private:
  std::vector<double> kbar_;  // the modified solver's last K̄
  bool replay_ = false;       // restore(): the next setup of the modified solver uses kbar_
  double last_h_ = 0.0;
};

}  // namespace shelldyn
