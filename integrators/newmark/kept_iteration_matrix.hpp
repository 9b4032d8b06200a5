// The iteration matrix K̄ that modified Newton keeps across steps, and what a checkpoint needs to continue
// with it bitwise (docs/architecture.md "Checkpoints and resume"): the last step size (K̄ depends on h),
// the K̄ in use, the iterations done with it and, with kbar_basis ≠ fixed, the configuration it was formed at,
// from which each later iteration sees it through a change of unknowns (docs/theory.md §6.9). Shared by
// em-galpha (and its family) and em-exact.
#pragma once

#include "elements/director.hpp"
#include "integrators/integrator.hpp"
#include "integrators/nonlinear/newton_solver.hpp"
#include "lib/model/semi_discrete_system.hpp"
#include "lib/linalg/sparse_matrix.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace shelldyn {

class KeptIterationMatrix {
 public:
  // How a kept K̄ is seen from later configurations (setting `kbar_basis`, docs/theory.md §6.9): `fixed` uses it
  // in the unknowns it was formed in; `charts` transforms it to the current director charts of nodes whose chart
  // switched since; `corotated` also rotates it with the best-fit rigid rotation of the body since (unconstrained
  // bodies only; others as `charts`).
  enum class Basis { fixed, charts, corotated };
  static Basis parse_basis(const std::string& v, const std::string& who) {
    if (v == "fixed") return Basis::fixed;
    if (v == "charts") return Basis::charts;
    if (v == "corotated") return Basis::corotated;
    throw std::invalid_argument(who + ".kbar_basis: '" + v + "' (use fixed, charts or corotated)");
  }
  void set_basis(Basis b) { basis_ = b; }

  // At the start of every step: a new h makes the kept K̄ useless. Steps that land on an output time differ from
  // Δt in the last bits (t_out − t); that is no reason to throw a factorization away.
  void start_step(double h, NewtonSolver& newton) {
    if (std::abs(h - last_h_) > 1e-8 * h) {
      newton.invalidate_jacobian();
      if (replay_) newton.resume_after_setup(0);  // a saved K̄ for another h is of no use
      replay_ = false;
    }
    last_h_ = h;
  }

  // The NewtonSolver::BasisProvider of a step (kbar_basis ≠ fixed; empty otherwise): the change of unknowns
  // from where K̄ was formed to the configuration mid(u_k) of the iterate (the midpoint K̄ is formed at), in the
  // step's charts. The references must outlive the solve.
  template <class Mid>
  NewtonSolver::BasisProvider provider(const SemiDiscreteSystem& sys, const std::vector<DirectorChart>& charts, Mid mid) {
    if (basis_ == Basis::fixed) return {};
    return [this, &sys, &charts, mid](const double* u, std::vector<NewtonSolver::BasisBlock>& blocks) {
      blocks.clear();
      if (u_ref_.size() == 0) return;
      mid(u, x_);
      if (sys.kept_matrix_basis(u_ref_, charts_ref_, x_, charts, basis_ == Basis::corotated, node_inverse_))
        make_blocks(blocks);
    };
  }

  // In the modified solver's Jacobian callback at the iterate u: the first setup after restore() takes the saved
  // K̄ (same values, hence the same factorization as the uninterrupted run) instead of a new one, seen through the
  // change the uninterrupted run used at this iterate; returns true then.
  bool replay(SparseMatrix& J, NewtonSolver& newton, const NewtonSolver::BasisProvider& basis, const double* u) {
    if (!replay_) return false;
    J.values = kbar_;
    replay_ = false;
    std::vector<NewtonSolver::BasisBlock> blocks;
    if (basis) {
      try {
        basis(u, blocks);
      } catch (const std::domain_error&) {  // the uninterrupted run formed a new K̄ here: so must this one
        newton.resume_after_setup(0);
        return false;
      }
    }
    newton.set_kept_basis_change(std::move(blocks));
    return true;
  }
  // In the modified solver's Jacobian callback after a new K̄ was formed at the configuration (u, charts)
  // (for save(), and as the reference of kbar_basis).
  void keep(const SparseMatrix& J, const Eigen::VectorXd& u, const std::vector<DirectorChart>& charts) {
    kbar_ = J.values;
    if (basis_ != Basis::fixed) {
      u_ref_ = u;
      charts_ref_ = charts;
    }
  }

  void save(IntegratorCheckpoint& c, const NewtonSolver& newton, bool modified) const {
    c.scalars["last_h"] = last_h_;
    const int since = modified ? newton.iterations_since_setup() : -1;
    c.scalars["newton_since_setup"] = since;
    if (since >= 0) c.vectors["kbar"] = Eigen::Map<const Eigen::VectorXd>(kbar_.data(), static_cast<Index>(kbar_.size()));
    if (since >= 0 && basis_ != Basis::fixed && u_ref_.size() > 0) {
      c.vectors["kbar_u_ref"] = u_ref_;
      Eigen::VectorXd ch(4 * static_cast<Index>(charts_ref_.size()));
      for (size_t i = 0; i < charts_ref_.size(); ++i)
        ch.segment<4>(4 * static_cast<Index>(i)) << charts_ref_[i].n, charts_ref_[i].m, charts_ref_[i].l,
            charts_ref_[i].s > 0 ? 1.0 : -1.0;  // as the state's charts (checkpoint.cpp)
      c.vectors["kbar_charts_ref"] = ch;
    }
  }

  // `who` names the integrator in the error; `sys` gives the sizes K̄ (its pattern) and the reference
  // configuration (its unknowns, 5 per node with one chart each) must have.
  void restore(const IntegratorCheckpoint& c, NewtonSolver& newton, bool modified, const SemiDiscreteSystem& sys,
               const std::string& who) {
    last_h_ = c.scalar("last_h");
    const int since = static_cast<int>(c.scalar("newton_since_setup"));
    replay_ = false;
    if (modified && since >= 0) {
      const Eigen::VectorXd& k = c.vector("kbar", sys.pattern()->nnz());
      kbar_.assign(k.data(), k.data() + k.size());
      replay_ = true;
      newton.resume_after_setup(since);
    }
    u_ref_.resize(0);
    charts_ref_.clear();
    if (c.vectors.count("kbar_u_ref")) {
      u_ref_ = c.vector("kbar_u_ref", sys.num_dofs());
      const Eigen::VectorXd& ch = c.vector("kbar_charts_ref", 4 * (sys.num_dofs() / kDofsPerNode));
      charts_ref_.resize(static_cast<size_t>(ch.size() / 4));
      for (size_t i = 0; i < charts_ref_.size(); ++i) {
        const Index k = 4 * static_cast<Index>(i);
        charts_ref_[i] = DirectorChart{static_cast<int>(ch[k]), static_cast<int>(ch[k + 1]), static_cast<int>(ch[k + 2]), ch[k + 3]};
        try {
          check_chart(charts_ref_[i]);
        } catch (const std::invalid_argument& e) {
          throw std::runtime_error(who + ": checkpoint kbar_charts_ref: " + e.what());
        }
      }
    }
  }

 private:
  // The node blocks of T⁻¹ (25 numbers per node, row-major kDofsPerNode² with the 3 × 3 and 2 × 2 blocks) as
  // NewtonSolver blocks, identity blocks left out.
  void make_blocks(std::vector<NewtonSolver::BasisBlock>& blocks) const {
    const size_t nn = node_inverse_.size() / 25;
    for (size_t i = 0; i < nn; ++i) {
      const double* B = node_inverse_.data() + 25 * i;
      const Index d0 = DofMap::dof(static_cast<int>(i), 0);
      for (int part = 0; part < 2; ++part) {
        const int off = part == 0 ? 0 : 3, size = part == 0 ? 3 : 2;
        NewtonSolver::BasisBlock b;
        b.first = d0 + off;
        b.size = size;
        bool identity = true;
        for (int r = 0; r < size; ++r)
          for (int c = 0; c < size; ++c) {
            b.inverse[3 * r + c] = B[5 * (off + r) + off + c];
            identity = identity && b.inverse[3 * r + c] == (r == c ? 1.0 : 0.0);
          }
        if (!identity) blocks.push_back(b);
      }
    }
  }

  Basis basis_ = Basis::fixed;
  Eigen::VectorXd u_ref_;                  // configuration K̄ was formed at (kbar_basis ≠ fixed)
  std::vector<DirectorChart> charts_ref_;  // its charts
  Eigen::VectorXd x_;                      // the iterate's midpoint configuration (provider())
  std::vector<double> node_inverse_;
  std::vector<double> kbar_;  // the modified solver's last K̄
  bool replay_ = false;       // restore(): the next setup of the modified solver uses kbar_
  double last_h_ = 0.0;
};

}  // namespace shelldyn
