// velocity-verlet: an explicit central-difference (velocity-Verlet) integrator for shelldyn, built as a plugin
// against the installed package (docs/tutorials/05-your-own-integrator.md). One step of size h from t_n:
//     v_{n+1/2} = v_n + h/2 a_n,   u_{n+1} = u_n + h v_{n+1/2},
//     M(u_{n+1}) a_{n+1} = F_ext(t_{n+1}, u_{n+1}) - F_int(u_{n+1}) - F_m(u_{n+1}, v_{n+1/2} + h/2 a_n),
//     v_{n+1} = v_{n+1/2} + h/2 a_{n+1},
// with the consistent mass matrix M(u) factorized every step (its director block depends on u), constrained
// rows replaced by identity rows (a = 0 there), and the external work by the trapezoidal rule
// W_{n+1} = W_n + 1/2 (F_ext,n + F_ext,n+1) . (u_{n+1} - u_n). Explicit, so stable only below the critical step
// of the mesh: `substeps` steps per time step of the case.
#include "integrators/integrator.hpp"
#include "integrators/runs/plugin.hpp"
#include "lib/model/assembler.hpp"
#include "lib/linalg/linear_solver.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace {

using namespace shelldyn;

class VelocityVerlet final : public Integrator {
 public:
  VelocityVerlet(IntegratorSettings& s, double dt) {
    substeps_ = s.get("substeps", 20);
    solver_name_ = s.get("linear_solver", "cholmod");
    hysteresis_ = s.get("hysteresis", 1.0);
    if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("velocity-verlet: time step dt must be > 0");
    if (substeps_ < 1) throw std::invalid_argument("velocity-verlet.substeps must be >= 1");
    if (hysteresis_ < 1.0) throw std::invalid_argument("velocity-verlet.hysteresis must be >= 1");
    h_ = dt / substeps_;
    settings_ = s.resolved();
  }

  std::string name() const override { return "velocity-verlet"; }
  std::vector<std::pair<std::string, std::string>> settings() const override { return settings_; }
  double external_work() const override { return w_ext_; }

  void initialize(SemiDiscreteSystem& sys, State& s) override {
    const Index n = sys.num_dofs();
    M_ = SparseMatrix{sys.pattern(), std::vector<double>(static_cast<size_t>(sys.pattern()->nnz()), 0.0)};
    solver_ = make_linear_solver(solver_name_);
    f_ext_.setZero(n), f_ext_new_.setZero(n), f_int_.setZero(n), f_m_.setZero(n);
    w_ext_ = 0.0;
    sys.rechart(s, hysteresis_);
    acceleration(sys, s.t, s.u, s.v, s.charts, f_ext_, s.a);  // the consistent initial acceleration
  }

  StepReport advance(SemiDiscreteSystem& sys, State& s, double t_out) override {
    StepReport rep;
    while (t_out - s.t > 1e-12 * h_) {
      if (stop_requested()) break;                        // at a step boundary: the driver checkpoints
      rep.chart_switches += sys.rechart(s, hysteresis_);  // between steps only (converts u, v, a)
      // The last step lands exactly on t_out and absorbs the round-off of summing steps (no sliver steps).
      const bool last = t_out - s.t <= h_ * (1.0 + 1e-6);
      const double h = last ? t_out - s.t : h_;
      sys.external(s.t, s.u, s.charts, f_ext_.data());    // F_ext,n in the current charts
      v_half_ = s.v + 0.5 * h * s.a;
      du_ = h * v_half_;
      u_new_ = s.u + du_;
      v_pred_ = v_half_ + 0.5 * h * s.a;
      // An explicit step above the critical step blows up: say so, whatever the system reports (e.g. a director
      // turned beyond its chart) or the solve gives (non-finite numbers).
      const auto where = [&] {
        return "velocity-verlet: step to t = " + std::to_string(s.t + h) + " (h = " + std::to_string(h) +
               ", above the critical step? raise substeps): ";
      };
      try {
        acceleration(sys, s.t + h, u_new_, v_pred_, s.charts, f_ext_new_, a_new_);
      } catch (const std::exception& e) {
        throw StepFailure(where() + e.what());
      }
      if (!a_new_.allFinite()) throw StepFailure(where() + "non-finite acceleration");
      w_ext_ += 0.5 * (f_ext_ + f_ext_new_).dot(du_);
      s.u = u_new_;
      s.v = v_half_ + 0.5 * h * a_new_;
      s.a = a_new_;
      s.t = last ? t_out : s.t + h;
      ++rep.steps;
      ++rep.factorizations;
      ++rep.rhs_evaluations;
      rep.last_dt = h;
    }
    return rep;
  }

  // Checkpoints: u, v, a are in the State; the scheme adds its external work only.
  void save(IntegratorCheckpoint& out) const override {
    out.scalars["w_ext"] = w_ext_;
    out.exact = true;  // a resumed run continues bitwise
  }
  void restore(SemiDiscreteSystem&, State&, const IntegratorCheckpoint& in) override { w_ext_ = in.scalar("w_ext"); }

 private:
  // a = M(u)^-1 (F_ext(t, u) - F_int(u) - F_m(u, v)) with a = 0 on constrained DOFs; F_ext(t, u) is left in f_ext.
  void acceleration(const SemiDiscreteSystem& sys, double t, const Eigen::VectorXd& u, const Eigen::VectorXd& v,
                    const std::vector<DirectorChart>& charts, Eigen::VectorXd& f_ext, Eigen::VectorXd& a) {
    M_.set_zero();
    sys.mass(u, charts, M_);
    sys.internal(u, charts, f_int_.data(), nullptr);
    sys.inertial(u, v, charts, f_m_.data());
    sys.external(t, u, charts, f_ext.data());
    rhs_ = f_ext - f_int_ - f_m_;
    apply_dirichlet(sys.dofs(), M_, rhs_.data());  // identity rows and columns, zero right-hand side
    solver_->factorize(M_.view());                   // analyses the pattern at the first call
    a.resize(rhs_.size());
    solver_->solve(rhs_.data(), a.data());
  }

  int substeps_ = 20;
  double h_ = 0.0, hysteresis_ = 1.0, w_ext_ = 0.0;
  std::string solver_name_;
  std::vector<std::pair<std::string, std::string>> settings_;
  SparseMatrix M_;
  std::unique_ptr<LinearSolver> solver_;
  Eigen::VectorXd f_ext_, f_ext_new_, f_int_, f_m_, rhs_, v_half_, du_, u_new_, v_pred_, a_new_;
};

}  // namespace

// The plugin's entry point: registers the scheme under the name `velocity-verlet`.
SHELLDYN_PLUGIN("1.0") {
  shelldyn::register_integrator("velocity-verlet",
                      "explicit central difference (velocity Verlet), consistent mass solved every step (example plugin)",
                      [](IntegratorSettings& s, double dt) { return std::make_unique<VelocityVerlet>(s, dt); });
}
