// Test-only C++ copy of the explicit central-difference / velocity-Verlet scheme of
// python/examples/verlet.py (docs/tutorials/10-python.md §4), operation for operation, so that the
// Python integrator can be checked against it to round-off (python/tests/test_python_integrator.py)
// and the cost of the Python call boundary measured. Compiled into the module, registered only on
// request: shelldyn._register_verlet_cpp(name).
//
// Scheme, one step of size h from (u_n, v_n, a_n) at t_n (charts re-selected before the step):
//   v_h     = v_n + h/2 a_n
//   u_{n+1} = u_n + h v_h
//   a_{n+1} = M(u_{n+1})⁻¹ [F_ext(t_{n+1}, u_{n+1}) − F_int(u_{n+1}) − F_m(u_{n+1}, v_h)]   (Dirichlet rows: a = 0)
//   v_{n+1} = v_h + h/2 a_{n+1}
//   W_ext  += ½ (F_ext(t_n, u_n) + F_ext(t_{n+1}, u_{n+1}))·(u_{n+1} − u_n)     (trapezoidal work)
// initialize(): charts selected, a_0 = M(u_0)⁻¹ [F_ext(0, u_0) − F_int(u_0) − F_m(u_0, v_0)].
// F_m is taken at the half-step velocity v_h (explicit; the gyroscopic term is then first order).
#include "python/src/bindings.hpp"

#include "integrators/integrator.hpp"
#include "integrators/runs/registry.hpp"
#include "lib/model/assembler.hpp"
#include "lib/linalg/linear_solver.hpp"

#include <chrono>
#include <sstream>

namespace shelldyn::python {
namespace {

class VerletCpp final : public Integrator {
 public:
  VerletCpp(std::string name, IntegratorSettings& s, double dt) : name_(std::move(name)), dt_(dt) {
    hysteresis_ = s.get("hysteresis", 1.0);
    solver_name_ = s.get("linear_solver", std::string("eigen-ldlt"));
    if (!(hysteresis_ >= 1.0)) throw std::invalid_argument("integrator.hysteresis: must be >= 1");
    if (!is_linear_solver_name(solver_name_)) throw std::invalid_argument("integrator.linear_solver: unknown solver '" + solver_name_ + "'");
  }
  std::string name() const override { return name_; }
  std::vector<std::pair<std::string, std::string>> settings() const override {
    std::ostringstream dt, hy;
    dt.precision(17);
    hy.precision(17);
    dt << dt_;
    hy << hysteresis_;
    return {{"dt", dt.str()}, {"hysteresis", hy.str()}, {"linear_solver", solver_name_}};
  }
  void initialize(SemiDiscreteSystem& sys, State& s) override {
    const Index n = sys.num_dofs();
    M_ = SparseMatrix{sys.pattern(), std::vector<double>(static_cast<size_t>(sys.pattern()->nnz()), 0.0)};
    solver_ = make_linear_solver(solver_name_);
    for (Eigen::VectorXd* v : {&f0_, &f1_, &fint_, &fm_, &r_, &vh_, &u1_}) v->setZero(n);
    work_ = 0.0;
    sys.rechart(s, hysteresis_);
    accelerate(sys, s.t, s.u, s.v, s.charts, s.a);
  }
  StepReport advance(SemiDiscreteSystem& sys, State& s, double t_out) override {
    const auto start = std::chrono::steady_clock::now();
    StepReport rep;
    while (s.t < t_out - 1e-12 * dt_) {  // the loop of python_integrator.cpp (and em_generalized_alpha.cpp)
      double h = std::min(dt_, t_out - s.t);
      if (t_out - (s.t + h) < 1e-9 * dt_) h = t_out - s.t;
      rep.chart_switches += sys.rechart(s, hysteresis_);
      step(sys, s, h);
      s.t = s.t + h;
      ++rep.steps;
      ++rep.rhs_evaluations;
      ++rep.factorizations;
      rep.last_dt = h;
      if (stop_requested()) break;
    }
    rep.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return rep;
  }
  double external_work() const override { return work_; }

 private:
  // a = M(u)⁻¹ [F_ext(t, u) − F_int(u) − F_m(u, v)], constrained entries 0; F_ext(t, u) left in f1_.
  void accelerate(SemiDiscreteSystem& sys, double t, const Eigen::VectorXd& u, const Eigen::VectorXd& v,
                  const std::vector<DirectorChart>& charts, Eigen::VectorXd& a) {
    sys.internal(u, charts, fint_.data(), nullptr);
    sys.inertial(u, v, charts, fm_.data());
    sys.external(t, u, charts, f1_.data());
    r_ = f1_ - fint_ - fm_;
    zero_constrained(sys.dofs(), r_.data());
    sys.mass(u, charts, M_);
    apply_dirichlet(sys.dofs(), M_, nullptr);
    solver_->factorize(M_.view());
    a.resize(u.size());
    solver_->solve(r_.data(), a.data());
  }
  void step(SemiDiscreteSystem& sys, State& s, double h) {
    sys.external(s.t, s.u, s.charts, f0_.data());
    vh_ = s.v + 0.5 * h * s.a;
    u1_ = s.u + h * vh_;
    Eigen::VectorXd a1;
    accelerate(sys, s.t + h, u1_, vh_, s.charts, a1);
    work_ += 0.5 * (f0_ + f1_).dot(u1_ - s.u);
    s.v = vh_ + 0.5 * h * a1;
    s.u = u1_;
    s.a = a1;
  }

  std::string name_;
  double dt_, hysteresis_ = 1.0;
  std::string solver_name_;
  SparseMatrix M_;
  std::unique_ptr<LinearSolver> solver_;
  Eigen::VectorXd f0_, f1_, fint_, fm_, r_, vh_, u1_;
  double work_ = 0.0;
};

}  // namespace

void register_test_integrators(py::module_& m) {
  m.def(
      "_register_verlet_cpp",
      [](const std::string& name) {
        register_integrator(
            name, "test-only C++ copy of the Python velocity-Verlet example (python/tests/verlet_cpp.cpp)",
            [name](IntegratorSettings& s, double dt) { return std::make_unique<VerletCpp>(name, s, dt); }, "shelldyn._testing");
      },
      py::arg("name") = "verlet-cpp",
      "Registers the test-only C++ copy of python/examples/verlet.py under `name`.");
}

}  // namespace shelldyn::python
