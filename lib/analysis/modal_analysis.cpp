// Shift-invert Lanczos on the free-DOF blocks of K and M (see the header and docs/modal.md).
#include "lib/analysis/modal_analysis.hpp"

#include "elements/director.hpp"
#include "lib/linalg/linear_solver.hpp"

#include <Spectra/SymGEigsShiftSolver.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace shelldyn {

std::string Mode::dominant() const {
  static const char* names[] = {"X", "Y", "Z", "rotation"};
  const auto k = static_cast<size_t>(std::max_element(share.begin(), share.end()) - share.begin());
  return names[k];
}

namespace {

using Clock = std::chrono::steady_clock;

// K_ff and M_ff on one reduced CSC pattern (full symmetric storage, sorted rows: free_index is monotone).
struct ReducedPair {
  SparsePattern pattern;
  std::vector<double> k, m, work;
  std::vector<Index> free_to_full;
};

ReducedPair reduce(const SparseMatrix& K, const SparseMatrix& M, const DofMap& dofs) {
  const SparsePattern& p = *K.pattern;
  ReducedPair r;
  r.pattern.n = dofs.num_free();
  r.pattern.colptr.assign(static_cast<size_t>(r.pattern.n) + 1, 0);
  for (Index j = 0; j < p.n; ++j) {
    const Index fj = dofs.free_index(j);
    if (fj < 0) continue;
    r.free_to_full.push_back(j);
    for (Index k = p.colptr[j]; k < p.colptr[j + 1]; ++k) {
      const Index fi = dofs.free_index(p.rowind[k]);
      if (fi < 0) continue;
      r.pattern.rowind.push_back(fi);
      r.k.push_back(K.values[static_cast<size_t>(k)]);
      r.m.push_back(M.values[static_cast<size_t>(k)]);
    }
    r.pattern.colptr[static_cast<size_t>(fj) + 1] = static_cast<Index>(r.pattern.rowind.size());
  }
  r.work.resize(r.k.size());
  return r;
}

// y = (K − σM)⁻¹ x through the project's LinearSolver (Spectra's OpType interface).
class ShiftInvertOp {
 public:
  using Scalar = double;
  ShiftInvertOp(ReducedPair& A, LinearSolver& solver) : A_(A), solver_(solver) {}
  Eigen::Index rows() const { return static_cast<Eigen::Index>(A_.pattern.n); }
  Eigen::Index cols() const { return rows(); }
  void set_shift(double sigma) {
    for (size_t i = 0; i < A_.k.size(); ++i) A_.work[i] = A_.k[i] - sigma * A_.m[i];
    const CscView v{A_.pattern.n, A_.pattern.colptr.data(), A_.pattern.rowind.data(), A_.work.data()};
    const auto t0 = Clock::now();
    solver_.factorize(v);
    factorize_s += std::chrono::duration<double>(Clock::now() - t0).count();
  }
  void perform_op(const double* x, double* y) const {
    solver_.solve(x, y);
    ++applications;
  }
  mutable long applications = 0;
  double factorize_s = 0.0;

 private:
  ReducedPair& A_;
  LinearSolver& solver_;
};

// y = M_ff x on full symmetric storage.
class MassOp {
 public:
  using Scalar = double;
  explicit MassOp(const ReducedPair& A) : A_(A) {}
  Eigen::Index rows() const { return static_cast<Eigen::Index>(A_.pattern.n); }
  Eigen::Index cols() const { return rows(); }
  void perform_op(const double* x, double* y) const {
    const auto& p = A_.pattern;
    std::fill(y, y + p.n, 0.0);
    for (Index j = 0; j < p.n; ++j)
      for (Index k = p.colptr[j]; k < p.colptr[j + 1]; ++k) y[p.rowind[k]] += A_.m[static_cast<size_t>(k)] * x[j];
  }

 private:
  const ReducedPair& A_;
};

}  // namespace

ModalResult modal_analysis(const Model& model, const State& state, const ModalOptions& o) {
  const auto start = Clock::now();
  const DofMap& dofs = model.dofs();
  const Index nf = dofs.num_free();
  if (o.num_modes < 1)
    throw std::invalid_argument("modal analysis: number of modes must be >= 1 (got " + std::to_string(o.num_modes) + ")");
  if (o.num_modes >= nf)
    throw std::invalid_argument("modal analysis: " + std::to_string(o.num_modes) + " modes asked but the model has only " +
                                std::to_string(nf) + " free DOFs (ask for fewer than " + std::to_string(nf) + ")");
  if (!(o.shift_hz >= 0.0) || !std::isfinite(o.shift_hz))
    throw std::invalid_argument("modal analysis: shift must be a frequency >= 0 Hz (got " + std::to_string(o.shift_hz) + ")");
  if (!(o.tol > 0.0) || o.max_restarts < 1 || !(o.rigid_tol >= 0.0))
    throw std::invalid_argument("modal analysis: need tol > 0, max_restarts >= 1, rigid_tol >= 0");

  SparseMatrix K = model.make_matrix(), M = model.make_matrix();
  model.internal(state.u, state.charts, nullptr, &K);
  if (o.load_stiffness) model.add_load_stiffness(state.t, state.u, state.charts, K);
  model.mass(state.u, state.charts, M);
  ReducedPair A = reduce(K, M, dofs);

  ModalResult r;
  r.free_dofs = nf;
  for (Index j = 0; j < nf; ++j)
    for (Index k = A.pattern.colptr[j]; k < A.pattern.colptr[j + 1]; ++k)
      if (A.pattern.rowind[k] == j) {
        const double mjj = A.m[static_cast<size_t>(k)];
        if (!(mjj > 0.0)) {
          std::ostringstream os;
          os << "modal analysis: mass matrix diagonal " << mjj << " at free DOF " << A.free_to_full[static_cast<size_t>(j)]
             << " is not positive (check rho and thickness)";
          throw std::runtime_error(os.str());
        }
        r.lambda_scale = std::max(r.lambda_scale, A.k[static_cast<size_t>(k)] / mjj);
      }
  r.sigma = o.shift_hz > 0.0 ? std::pow(2.0 * M_PI * o.shift_hz, 2) : -1e-9 * r.lambda_scale;

  auto solver = make_linear_solver(o.linear_solver);
  ShiftInvertOp op(A, *solver);
  MassOp bop(A);
  // Lanczos can miss copies of a multiple eigenvalue (the six rigid modes, symmetric pairs). For the
  // lowest modes a Sturm-sequence count checks the result: the negative pivots of LDLᵀ(K − τM) are the
  // number of eigenvalues below τ (Sylvester). If more lie below the top computed one than were found,
  // the search is repeated with a larger subspace (up to three times, then an error).
  auto sturm = make_linear_solver("eigen-ldlt");
  ReducedPair S = A;
  Eigen::Index nev = o.num_modes;
  for (int attempt = 0;; ++attempt) {
    Eigen::VectorXd lam;
    Eigen::MatrixXd vec;
    try {
      const Eigen::Index ncv = std::min<Eigen::Index>(nf, std::max<Eigen::Index>(2 * nev + 1, nev + 20));
      Spectra::SymGEigsShiftSolver<ShiftInvertOp, MassOp, Spectra::GEigsMode::ShiftInvert> eigs(op, bop, nev, ncv, r.sigma);
      eigs.init();
      eigs.compute(Spectra::SortRule::LargestMagn, o.max_restarts, o.tol, Spectra::SortRule::SmallestAlge);
      if (eigs.info() != Spectra::CompInfo::Successful) {
        std::ostringstream os;
        os << "modal analysis: Spectra did not converge (" << eigs.num_iterations() << " restarts, " << op.applications
           << " solves, tol " << o.tol << "); ask for fewer modes or a larger tolerance";
        throw std::runtime_error(os.str());
      }
      r.restarts += static_cast<int>(eigs.num_iterations());
      lam = eigs.eigenvalues();
      vec = eigs.eigenvectors();
    } catch (const std::runtime_error&) {
      throw;
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string("modal analysis: ") + e.what());
    }
    std::vector<Eigen::Index> order(static_cast<size_t>(lam.size()));
    for (Eigen::Index i = 0; i < lam.size(); ++i) order[static_cast<size_t>(i)] = i;
    std::sort(order.begin(), order.end(), [&](Eigen::Index x, Eigen::Index y) { return lam[x] < lam[y]; });
    order.resize(static_cast<size_t>(o.num_modes));
    if (o.shift_hz == 0.0) {
      const double top = lam[order.back()];
      // τ just below the top computed value: a multiple eigenvalue cut by num_modes is not a miss.
      const double tau = top - 1e-6 * std::abs(top) - 1e-12 * r.lambda_scale;
      long computed_below = 0;
      for (Eigen::Index i : order) computed_below += lam[i] < tau ? 1 : 0;
      for (size_t i = 0; i < S.k.size(); ++i) S.work[i] = S.k[i] - tau * S.m[i];
      sturm->factorize({S.pattern.n, S.pattern.colptr.data(), S.pattern.rowind.data(), S.work.data()});
      const long below = sturm->negative_pivots();
      r.sturm_count = below;
      if (below > computed_below) {
        if (attempt == 3) {
          std::ostringstream os;
          os << "modal analysis: the Sturm count finds " << below << " eigenvalues below omega^2 = " << tau << " but "
             << computed_below << " were computed (missed multiple eigenvalues); try more modes (-n)";
          throw std::runtime_error(os.str());
        }
        nev += below - computed_below + 4;
        if (nev >= nf) nev = nf - 1;
        continue;
      }
    }
    Eigen::VectorXd mphi(nf);
    for (Eigen::Index i : order) {
      Mode m;
      m.omega2 = lam[i];
      m.rigid = std::abs(m.omega2) <= o.rigid_tol * r.lambda_scale;
      m.unstable = !m.rigid && m.omega2 < 0.0;  // the tangent is indefinite: no real frequency
      m.omega = (m.rigid || m.unstable) ? 0.0 : std::sqrt(m.omega2);
      m.frequency = m.omega / (2.0 * M_PI);
      m.period = (m.rigid || m.unstable) ? std::numeric_limits<double>::infinity() : 2.0 * M_PI / m.omega;
      r.unstable_modes += m.unstable ? 1 : 0;
      Eigen::VectorXd phi = vec.col(i);
      bop.perform_op(phi.data(), mphi.data());
      const double norm2 = phi.dot(mphi);
      phi /= std::sqrt(norm2);
      mphi /= std::sqrt(norm2);
      m.shape = Eigen::VectorXd::Zero(model.num_dofs());
      for (Index f = 0; f < nf; ++f) {
        const Index d = A.free_to_full[static_cast<size_t>(f)];
        m.shape[d] = phi[f];
        m.share[static_cast<size_t>(std::min<Index>(d % kDofsPerNode, 3))] += phi[f] * mphi[f];
      }
      r.rigid_modes += m.rigid ? 1 : 0;
      r.modes.push_back(std::move(m));
    }
    break;
  }
  r.operator_applications = op.applications;
  r.factorize_s = op.factorize_s;
  r.total_s = std::chrono::duration<double>(Clock::now() - start).count();
  return r;
}

std::vector<double> elastic_periods(const ModalResult& r, int count) {
  std::vector<double> T;
  for (const Mode& m : r.modes)
    if (!m.rigid && static_cast<int>(T.size()) < count) T.push_back(m.period);
  return T;
}

void write_mode_shapes_csv(const std::string& path, const Model& model, const State& state, const ModalResult& r) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path + " (check the folder and its permissions)");
  out << "mode,node,ux,uy,uz,pdx,pdy,pdz\n";
  char buf[320];
  const int nodes = model.mesh().num_nodes();
  for (size_t k = 0; k < r.modes.size(); ++k) {
    const Eigen::VectorXd& phi = r.modes[k].shape;
    for (int i = 0; i < nodes; ++i) {
      const Index base = DofMap::dof(i, 0);
      const Eigen::Vector2d q = state.u.segment<2>(base + 3);
      // δp = A1(q) δq: the director change of the mode (docs/theory.md §2.2), tangent to p.
      const Eigen::Vector3d dp = director_A1(q, state.charts[static_cast<size_t>(i)]) * phi.segment<2>(base + 3);
      std::snprintf(buf, sizeof buf, "%zu,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", k + 1, i, phi[base], phi[base + 1],
                    phi[base + 2], dp.x(), dp.y(), dp.z());
      out << buf;
    }
  }
  out.flush();
  if (!out) throw std::runtime_error("cannot write " + path + " (disk full?)");
}

}  // namespace shelldyn
