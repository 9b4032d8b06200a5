// Checkpoint/restart (integrators/checkpoint/checkpoint.hpp, Integrator::save/restore,
// docs/architecture.md "Checkpoints and resume"): file round trip bit for bit, damaged files rejected,
// the Newmark family continuing bitwise (also after a stop request in the middle of an output interval,
// and with modified Newton whose K̄ and refresh count must be restored, at every phase of the refresh
// count), em-exact likewise (with its director velocities State::pdot), the SUNDIALS re-initialization
// agreeing to its tolerance, and the default of a new integrator.
#include "baseline_cases.hpp"
#include "dynamics_fixtures.hpp"

#include "integrators/checkpoint/checkpoint.hpp"
#include "lib/io/run_info.hpp"
#include "integrators/runs/registry.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <functional>
#include <limits>
#include <sstream>

namespace shelldyn {
namespace {
using namespace baseline_cases;

namespace fs = std::filesystem;

// One folder per test and name: ctest -j runs tests of this binary in parallel processes, and several tests
// checkpoint the same integrator at the same phase (a shared folder made them read each other's files).
std::string scratch(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string test = info ? std::string(info->test_suite_name()) + "." + info->name() + "_" : "";
  const fs::path d = fs::path(::testing::TempDir()) / ("shelldyn_ckpt_" + test + name);
  fs::create_directories(d);
  return (d / "checkpoint.cbor").string();
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0);
}

TEST(Checkpoint, FileRoundTripIsBitExact) {
  Checkpoint c;
  c.state.t = 0.1 + 0.2;
  c.state.u = Eigen::VectorXd::LinSpaced(7, -1.0 / 3.0, 2.0 / 3.0);
  c.state.v = Eigen::VectorXd::Constant(7, -0.0);
  c.state.a = Eigen::VectorXd::Constant(7, std::numeric_limits<double>::denorm_min());
  c.state.charts = {DirectorChart{0, 1, 2, 1.0}, DirectorChart{1, 2, 0, -1.0}};
  c.integrator = "em-galpha";
  c.integrator_data.exact = true;
  c.integrator_data.scalars["W_ext"] = std::nextafter(1.0, 2.0);
  c.integrator_data.scalars["nan"] = std::numeric_limits<double>::quiet_NaN();
  c.integrator_data.vectors["kbar"] = Eigen::VectorXd::Random(11);
  c.numbers["steps"] = 123456789.0;
  c.texts["case_text"] = std::string("name: x\n\0binary\xff", 17);
  c.vectors["empty"] = Eigen::VectorXd();
  const std::string path = scratch("roundtrip");
  write_checkpoint(path, c);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  const Checkpoint r = read_checkpoint(path);
  EXPECT_TRUE(same_bits(r.state.t, c.state.t));
  EXPECT_TRUE(same_bits(r.state.u, c.state.u));
  EXPECT_TRUE(same_bits(r.state.v, c.state.v));  // -0 stays -0
  EXPECT_TRUE(same_bits(r.state.a, c.state.a));
  ASSERT_EQ(r.state.charts.size(), 2u);
  EXPECT_EQ(r.state.charts[1].n, 1);
  EXPECT_EQ(r.state.charts[1].l, 0);
  EXPECT_EQ(r.state.charts[1].s, -1.0);
  EXPECT_EQ(r.integrator, "em-galpha");
  EXPECT_TRUE(r.integrator_data.exact);
  EXPECT_TRUE(same_bits(r.integrator_data.scalar("W_ext"), c.integrator_data.scalars["W_ext"]));
  EXPECT_TRUE(std::isnan(r.integrator_data.scalar("nan")));
  EXPECT_TRUE(same_bits(r.integrator_data.vector("kbar"), c.integrator_data.vectors["kbar"]));
  EXPECT_EQ(r.number("steps"), 123456789.0);
  EXPECT_EQ(r.text("case_text"), c.texts["case_text"]);
  EXPECT_EQ(r.vector("empty").size(), 0);
  EXPECT_THROW(r.number("absent"), std::runtime_error);
}

TEST(Checkpoint, DamagedOrMissingFilesAreRejectedWithOneLine) {
  const std::string path = scratch("damaged");
  {
    std::ofstream out(path, std::ios::binary);
    out << "not a checkpoint";
  }
  try {
    read_checkpoint(path);
    FAIL() << "a damaged file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("damaged checkpoint"), std::string::npos) << e.what();
  }
  // A valid checkpoint cut short (a crash while copying it, say).
  Checkpoint c;
  c.state.u = c.state.v = c.state.a = Eigen::VectorXd::Ones(50);
  write_checkpoint(path, c);
  const auto size = fs::file_size(path);
  fs::resize_file(path, size / 2);
  EXPECT_THROW(read_checkpoint(path), std::runtime_error);
  EXPECT_THROW(read_checkpoint(path + ".absent"), std::runtime_error);
}

// A checkpoint of format 1 (before checksums) is read, but resuming from it needs --allow-other-version: its
// integrity cannot be checked (check_checkpoint_origin).
TEST(Checkpoint, FormatOneWithoutChecksumNeedsAllowOtherVersion) {
  const std::string path = scratch("format1");
  Checkpoint c;
  c.state.t = 0.5;
  c.state.u = c.state.v = c.state.a = Eigen::VectorXd::LinSpaced(6, 0.0, 1.0);
  c.integrator = "em-galpha";
  c.numbers["steps"] = 3;
  write_checkpoint(path, c);
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  // Unwrap the integrity envelope: format 1 was the body document itself, with its format and version.
  const nlohmann::json w = nlohmann::json::from_cbor(bytes);
  const auto& body = w.at("body").get_binary();
  nlohmann::json j = nlohmann::json::from_cbor(std::vector<std::uint8_t>(body.begin(), body.end()));
  j["format"] = w.at("format");
  j["version"] = 1;
  {
    const std::vector<std::uint8_t> out = nlohmann::json::to_cbor(j);
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(out.data()), static_cast<std::streamsize>(out.size()));
  }
  const Checkpoint r = read_checkpoint(path);
  EXPECT_TRUE(r.made_by.empty());
  EXPECT_EQ(r.state.t, 0.5);
  EXPECT_EQ(r.number("steps"), 3.0);
  try {
    check_checkpoint_origin(r, path, false, false, nullptr);
    ADD_FAILURE() << "a format-1 checkpoint was accepted without --allow-other-version";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("--allow-other-version"), std::string::npos) << e.what();
  }
  std::ostringstream note;
  EXPECT_NO_THROW(check_checkpoint_origin(r, path, false, true, &note));
  EXPECT_NE(note.str().find("without checksum"), std::string::npos) << note.str();
}

// Integrity (checkpoint.hpp): every single-bit flip anywhere in a checkpoint is refused as damaged, and a
// checkpoint records the shelldyn version that wrote it.
TEST(Checkpoint, EverySingleBitFlipIsRefused) {
  const std::string path = scratch("flips");
  Checkpoint c;
  c.state.t = 0.25;
  c.state.u = c.state.v = c.state.a = Eigen::VectorXd::LinSpaced(12, -1.0, 1.0);
  c.integrator = "em-galpha";
  c.integrator_data.scalars["W_ext"] = 1.5;
  c.numbers["steps"] = 25;
  c.texts["case_text"] = "name: x\n";
  write_checkpoint(path, c);
  EXPECT_EQ(read_checkpoint(path).made_by, shelldyn_version());
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  ASSERT_GT(bytes.size(), 100u);
  int refused = 0, accepted = 0;
  for (size_t bit = 0; bit < 8 * bytes.size(); ++bit) {
    std::string b = bytes;
    b[bit / 8] = static_cast<char>(b[bit / 8] ^ (1 << (bit % 8)));
    {
      std::ofstream out(path, std::ios::binary | std::ios::trunc);
      out << b;
    }
    try {
      read_checkpoint(path);
      ++accepted;
    } catch (const std::runtime_error& e) {
      const std::string w = e.what();
      EXPECT_EQ(w.find('\n'), std::string::npos) << w;  // one line
      ++refused;
    }
  }
  EXPECT_EQ(accepted, 0) << "of " << 8 * bytes.size() << " single-bit flips";
  EXPECT_EQ(refused, static_cast<int>(8 * bytes.size()));
}

class NoCheckpoints final : public Integrator {
 public:
  std::string name() const override { return "toy"; }
  std::vector<std::pair<std::string, std::string>> settings() const override { return {}; }
  void initialize(SemiDiscreteSystem&, State&) override {}
  StepReport advance(SemiDiscreteSystem&, State& s, double t_out) override {
    s.t = t_out;
    return {};
  }
  double external_work() const override { return 0.0; }
};

TEST(Checkpoint, NewIntegratorsCompileUnchangedAndSayWhatIsMissing) {
  NoCheckpoints toy;
  IntegratorCheckpoint c;
  try {
    toy.save(c);
    FAIL() << "save() of an integrator without checkpoints did not throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("integrator toy does not support checkpoints"), std::string::npos);
  }
}

// Runs `name` on a fast-spinning plate that switches director charts, uninterrupted to t2 and, in a
// second run, stopped after `stop_after` steps of the interval (t1, t2] (a stop request as SIGINT makes),
// saved through a checkpoint FILE into a fresh model and integrator, and continued to t2. The continuing
// integrator is made with `resume_settings` if given (as `shelldyn resume` makes it from the command line).
void expect_bitwise_continuation(const std::string& name, std::vector<std::pair<std::string, std::string>> settings,
                                 int stop_after, double dt = 0.01, bool require_switches = true,
                                 const std::vector<std::pair<std::string, std::string>>* resume_settings = nullptr) {
  const double t1 = 20 * dt, t2 = 50 * dt;
  auto run_a = [&](std::unique_ptr<Model>& model) {
    IntegratorSettings s(name, settings);
    auto integ = make_integrator(s, dt);
    State st = spin_state(*model, Vec3(3.0, 0.4, 0.2));
    integ->initialize(*model, st);
    StepReport rep;
    rep.accumulate(integ->advance(*model, st, t1));
    rep.accumulate(integ->advance(*model, st, t2));
    return std::make_tuple(st, integ->external_work(), rep);
  };
  auto model_a = spin_plate(1e4);
  const auto [ref, ref_work, ref_rep] = run_a(model_a);
  if (require_switches) {
    ASSERT_GT(ref_rep.chart_switches, 0) << "the case must exercise chart switches";
  }

  // Run B, part 1.
  const std::string path = scratch(name + std::to_string(stop_after));
  StepReport rep_b;
  {
    auto model = spin_plate(1e4);
    IntegratorSettings s(name, settings);
    auto integ = make_integrator(s, dt);
    State st = spin_state(*model, Vec3(3.0, 0.4, 0.2));
    integ->initialize(*model, st);
    rep_b.accumulate(integ->advance(*model, st, t1));
    int steps = 0;
    integ->set_stop_request([&] { return ++steps >= stop_after; });
    rep_b.accumulate(integ->advance(*model, st, t2));
    ASSERT_LT(st.t, t2) << "the stop request was not honoured";
    Checkpoint c;
    c.state = st;
    c.integrator = integ->name();
    integ->save(c.integrator_data);
    EXPECT_TRUE(c.integrator_data.exact);
    write_checkpoint(path, c);
  }
  // Run B, part 2: everything new, as `shelldyn resume` has it.
  const Checkpoint c = read_checkpoint(path);
  auto model = spin_plate(1e4);
  IntegratorSettings s(name, resume_settings ? *resume_settings : settings);
  auto integ = make_integrator(s, dt);
  State st = model->initial_state();
  integ->initialize(*model, st);
  st = c.state;
  model->adopt_charts(st.charts);
  integ->restore(*model, st, c.integrator_data);
  rep_b.accumulate(integ->advance(*model, st, t2));

  EXPECT_TRUE(same_bits(st.t, ref.t));
  EXPECT_TRUE(same_bits(st.u, ref.u)) << name << ": max |du| = " << (st.u - ref.u).cwiseAbs().maxCoeff();
  EXPECT_TRUE(same_bits(st.v, ref.v)) << name << ": max |dv| = " << (st.v - ref.v).cwiseAbs().maxCoeff();
  EXPECT_TRUE(same_bits(st.a, ref.a)) << name << ": max |da| = " << (st.a - ref.a).cwiseAbs().maxCoeff();
  EXPECT_TRUE(same_bits(st.pdot, ref.pdot)) << name << ": director velocities differ (sizes " << st.pdot.size() << ", "
                                            << ref.pdot.size() << ")";
  EXPECT_TRUE(same_bits(integ->external_work(), ref_work));
  for (size_t i = 0; i < st.charts.size(); ++i) EXPECT_EQ(st.charts[i].l, ref.charts[i].l) << "node " << i;
  EXPECT_EQ(rep_b.steps, ref_rep.steps);
  EXPECT_EQ(rep_b.nonlinear_iterations, ref_rep.nonlinear_iterations);
  EXPECT_EQ(rep_b.linear_setups, ref_rep.linear_setups) << "a replayed K̄ must not count as a new setup";
}

TEST(CheckpointNewmark, EmGalphaModifiedNewtonContinuesBitwise) {
  // setup_every 3: K̄ is refreshed every 3 iterations across steps, so both the saved K̄ and the
  // refresh count matter at the restart.
  expect_bitwise_continuation("em-galpha", {{"newton", "modified"}, {"setup_every", "3"}}, 7);
  expect_bitwise_continuation("em-galpha", {{"newton", "modified"}, {"setup_every", "3"}}, 1);
}
TEST(CheckpointNewmark, EmGalphaModifiedNewtonDefaultsContinueBitwise) {
  // The modified-Newton defaults: K̄ kept across steps and refreshed by observed contraction, Newmark
  // predictor, energy floor e_floor·(K_0 + V_0 + |W_ext|) whose K_0 + V_0 (taken at initialize()) must come
  // from the checkpoint, not from the state the resumed integrator was initialized with.
  expect_bitwise_continuation("em-galpha", {{"newton", "modified"}}, 7);
  expect_bitwise_continuation("em-galpha", {{"newton", "modified"}}, 1);
  // cc_tol out of reach: the energy floor (or the step test) ends every iteration.
  expect_bitwise_continuation("em-galpha", {{"newton", "modified"}, {"cc_tol", "1e-30"}}, 7);
}
TEST(CheckpointNewmark, SinglePrecisionSolvesContinueBitwise) {
  // solve_precision = single (docs/dependencies.md §5.5): the replayed K̄ is factorized and copied to float again,
  // which must give the same float factor, hence the same corrections.
  expect_bitwise_continuation("em-galpha", {{"newton", "modified"}, {"solve_precision", "single"}}, 7);
  expect_bitwise_continuation("em-exact", {{"newton", "modified"}, {"setup_every", "2"}, {"solve_precision", "single"}}, 3);
}
TEST(CheckpointNewmark, EmGalphaFullNewtonContinuesBitwise) { expect_bitwise_continuation("em-galpha", {}, 5); }
TEST(CheckpointNewmark, GalphaContinuesBitwise) { expect_bitwise_continuation("galpha", {{"rho_inf", "0.8"}}, 5); }
TEST(CheckpointNewmark, MidpointContinuesBitwise) { expect_bitwise_continuation("midpoint", {}, 5); }
TEST(CheckpointNewmark, NewmarkContinuesBitwise) { expect_bitwise_continuation("newmark", {}, 5); }
TEST(CheckpointNewmark, EmGalphaModifiedNewtonAtEveryRefreshPhase) {
  // Cut after 1..6 steps: among them the cuts where the saved K̄ has used up its setup_every iterations
  // (the next iteration refreshes it; replaying it would be wrong).
  for (int stop_after = 1; stop_after <= 6; ++stop_after)
    expect_bitwise_continuation("em-galpha", {{"newton", "modified"}, {"setup_every", "2"}}, stop_after);
}

using Settings = std::vector<std::pair<std::string, std::string>>;

// Runs `integrator` with `begun` over 5 steps of a spinning plate, saves it, lets `edit` change the checkpoint,
// and restores that into a fresh integrator made with `resumed`, which it returns (restore() may throw).
std::unique_ptr<Integrator> resumed_after_five_steps(Model& model, const std::string& integrator, const Settings& begun,
                                                     const Settings& resumed,
                                                     const std::function<void(IntegratorCheckpoint&)>& edit) {
  IntegratorSettings s0(integrator, begun);
  auto first = make_integrator(s0, 0.01);
  State st = spin_state(model, Vec3(3.0, 0.4, 0.2));
  first->initialize(model, st);
  first->advance(model, st, 0.05);
  IntegratorCheckpoint c;
  first->save(c);
  edit(c);
  IntegratorSettings s1(integrator, resumed);
  auto second = make_integrator(s1, 0.01);
  State fresh = model.initial_state();
  second->initialize(model, fresh);
  second->restore(model, st, c);
  return second;
}

// Saves `integrator` (modified Newton) after 5 steps of a spinning plate, lets `damage` change the checkpoint as a
// damaged file would, and expects restore() to refuse it with a runtime_error that names `key`.
void expect_damaged_checkpoint_refused(const std::string& integrator, const std::string& key,
                                       const std::function<void(IntegratorCheckpoint&)>& damage) {
  auto model = spin_plate(1e4);
  const Settings modified = {{"newton", "modified"}};
  try {
    resumed_after_five_steps(*model, integrator, modified, modified, [&](IntegratorCheckpoint& c) {
      ASSERT_EQ(c.vectors.count(key), 1u) << key;
      damage(c);
    });
    FAIL() << "a damaged " << key << " was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
  }
}

TEST(CheckpointNewmark, DamagedKbarReferenceChartsAreRejected) {
  // kbar_basis (docs/theory.md §6.9): the checkpoint keeps the configuration and charts the kept K̄ was formed
  // at; a chart that is not a permutation (a damaged file) is refused on restore, as the state's charts are.
  expect_damaged_checkpoint_refused("em-galpha", "kbar_charts_ref", [](IntegratorCheckpoint& c) {
    ASSERT_EQ(c.vectors.count("kbar_u_ref"), 1u);
    c.vectors["kbar_charts_ref"][0] = 7.0;
  });
  // The configuration K̄ was formed at must have the system's unknowns, all finite.
  expect_damaged_checkpoint_refused("em-galpha", "kbar_u_ref", [](IntegratorCheckpoint& c) {
    Eigen::VectorXd& u = c.vectors["kbar_u_ref"];
    u.conservativeResize(u.size() - 1);
  });
  expect_damaged_checkpoint_refused("em-galpha", "kbar_u_ref", [](IntegratorCheckpoint& c) {
    c.vectors["kbar_u_ref"][2] = std::numeric_limits<double>::infinity();
  });
}

// em-exact carries the embedded director velocities (State::pdot), its own diagnostics and the predictor's
// director accelerations (docs/theory/exact-energy-momentum.md §5.7): a vector of the wrong length or with a
// non-finite entry (a damaged file) is refused on restore with its key named.
TEST(CheckpointEmExact, DamagedDirectorAccelerationIsRejected) {
  expect_damaged_checkpoint_refused("em-exact", "director_acceleration", [](IntegratorCheckpoint& c) {
    Eigen::VectorXd& wd = c.vectors["director_acceleration"];
    ASSERT_GT(wd.norm(), 0.0);  // a spinning plate's directors accelerate
    wd.conservativeResize(wd.size() - 1);
  });
  expect_damaged_checkpoint_refused("em-exact", "director_acceleration", [](IntegratorCheckpoint& c) {
    c.vectors["director_acceleration"][1] = std::numeric_limits<double>::quiet_NaN();
  });
}

TEST(CheckpointEmExact, FullNewtonContinuesBitwise) { expect_bitwise_continuation("em-exact", {}, 5); }
TEST(CheckpointEmExact, DissipativeContinuesBitwise) { expect_bitwise_continuation("em-exact", {{"rho_inf", "0.8"}, {"max_cuts", "3"}}, 3); }
TEST(CheckpointEmExact, ModifiedNewtonContinuesBitwiseAtEveryRefreshPhase) {
  for (int stop_after = 1; stop_after <= 6; ++stop_after)
    expect_bitwise_continuation("em-exact", {{"newton", "modified"}, {"setup_every", "2"}}, stop_after);
}

// certify = predicted measures the floor only every 16th step (theory §5.4): the continued run must keep that
// schedule and the ring of measured floors. Stops on both sides of the measuring step 32.
TEST(CheckpointEmExact, PredictedCertifyContinuesBitwise) {
  for (int stop_after : {1, 11, 12, 13})
    expect_bitwise_continuation("em-exact", {{"newton", "modified"}, {"certify", "predicted"}}, stop_after);
}

// certify = energy (theory §5.10): the floor is relative to K + V at the start of the run, which the checkpoint
// carries; initialize() on the restored state would take that state's energy instead.
TEST(CheckpointEmExact, EnergyCertifyContinuesBitwise) {
  for (int stop_after : {1, 12}) expect_bitwise_continuation("em-exact", {{"newton", "modified"}, {"certify", "energy"}}, stop_after);
}

// predictor = newmark (theory §5.9) carries the end-point accelerations of its recursion, which every later
// predictor depends on: saved, the run continues bitwise. A checkpoint written with another predictor has no
// such vectors; resumed with newmark, the recursion restarts from the consistent acceleration of the restored
// state (finite, saved again at the next checkpoint) instead of failing.
TEST(CheckpointEmExact, NewmarkPredictorContinuesBitwise) {
  const Settings newmark = {{"newton", "modified"}, {"predictor", "newmark"}};
  for (int stop_after : {1, 12}) expect_bitwise_continuation("em-exact", newmark, stop_after);
  auto model = spin_plate(1e4);
  const Settings trapezoidal = {{"newton", "modified"}};
  const auto second = resumed_after_five_steps(*model, "em-exact", trapezoidal, newmark, [](IntegratorCheckpoint& c) {
    EXPECT_EQ(c.vectors.count("newmark_acceleration"), 0u);
  });
  IntegratorCheckpoint again;
  second->save(again);
  const Index nn = model->mesh().num_nodes();
  EXPECT_GT(again.vector("newmark_acceleration", 3 * nn).norm(), 0.0);  // a spinning plate's nodes accelerate
  EXPECT_GT(again.vector("newmark_director_acceleration", 3 * nn).norm(), 0.0);
}

// certify = auto (theory §5.8): a resumed run keeps the rule it started with. A run begun with certify = floor
// (what auto meant before the fifteenth session) and resumed without the setting continues bitwise as floor,
// and says so in its settings (run.json); a checkpoint without the record is read as floor.
TEST(CheckpointEmExact, CertifyAutoKeepsTheRuleTheRunStartedWith) {
  const Settings floor = {{"newton", "modified"}, {"certify", "floor"}};
  const Settings automatic = {{"newton", "modified"}};
  for (int stop_after : {1, 12}) expect_bitwise_continuation("em-exact", floor, stop_after, 0.01, true, &automatic);
  auto certify_after_restore = [&](const Settings& begun, bool drop_record) {
    auto model = spin_plate(1e4);
    const auto second = resumed_after_five_steps(*model, "em-exact", begun, automatic, [&](IntegratorCheckpoint& c) {
      if (drop_record) c.scalars.erase("certify_rule");
    });
    for (const auto& [key, value] : second->settings())
      if (key == "certify") return value;
    return std::string("(none)");
  };
  EXPECT_EQ(certify_after_restore(floor, false), "floor");
  EXPECT_EQ(certify_after_restore(floor, true), "floor");
  EXPECT_EQ(certify_after_restore(automatic, false), "predicted");
  EXPECT_EQ(certify_after_restore(automatic, true), "floor");  // an old checkpoint: auto meant floor
  // A run begun with certify = energy (theory §5.10) and resumed without the setting continues bitwise with it.
  const Settings energy = {{"newton", "modified"}, {"certify", "energy"}};
  expect_bitwise_continuation("em-exact", energy, 12, 0.01, true, &automatic);
  EXPECT_EQ(certify_after_restore(energy, false), "energy");
}

// The renewal refresh (refresh_cost, theory §5.5) counts steps and iterations since the last refresh of K̄: the
// continued run must keep the count.
// At Δt 0.001 the plate keeps K̄ over several steps (at 0.01 it refreshes at every step, so the count would not
// be exercised); in these 50 steps it switches no chart, which the other tests cover.
TEST(CheckpointEmExact, RenewalRefreshContinuesBitwise) {
  for (int stop_after = 1; stop_after <= 8; ++stop_after)
    expect_bitwise_continuation("em-exact", {{"newton", "modified"}, {"refresh_cost", "12"}}, stop_after, 0.001, false);
}

// ida-bdf restarts from the saved state (re-initialization): not bitwise; the continued run must agree
// with the uninterrupted one to the level of its tolerances. Measured: see the bound below.
TEST(CheckpointSundials, IdaBdfRestartsFromTheSavedState) {
  const double t1 = 0.02, t2 = 0.05;
  const std::vector<std::pair<std::string, std::string>> settings{{"rtol", "1e-8"}, {"atol", "1e-10"}};
  auto model_a = flight_plate();
  IntegratorSettings sa("ida-bdf", settings);
  auto ia = make_integrator(sa, 1e-3);
  State a = flight_state(*model_a);
  ia->initialize(*model_a, a);
  ia->advance(*model_a, a, t1);
  IntegratorCheckpoint saved;
  ia->save(saved);
  EXPECT_FALSE(saved.exact);
  const State at_t1 = a;
  ia->advance(*model_a, a, t2);

  auto model_b = flight_plate();
  IntegratorSettings sb("ida-bdf", settings);
  auto ib = make_integrator(sb, 1e-3);
  State b = model_b->initial_state();
  ib->initialize(*model_b, b);
  b = at_t1;
  model_b->adopt_charts(b.charts);
  ib->restore(*model_b, b, saved);
  ib->advance(*model_b, b, t2);
  const double du = (b.u - a.u).cwiseAbs().maxCoeff() / a.u.cwiseAbs().maxCoeff();
  const double dw = std::abs(ib->external_work() - ia->external_work());
  EXPECT_LT(du, 1e-6) << "relative displacement difference " << du;
  EXPECT_LT(dw, 1e-9);
  EXPECT_EQ(b.t, a.t);
}

}  // namespace
}  // namespace shelldyn
