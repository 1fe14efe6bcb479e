// Checkpoint and restore: a run restored at step k and continued gives the
// same bits as the uninterrupted run, for every method; truncated, corrupted
// and foreign checkpoints are rejected with an error that says why.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <fstream>

#include "core/byte_stream.h"
#include "gssm/checkpoint/checkpoint.h"
#include "gssm/estimator/estimator.h"
#include "gssm/models/linear.h"
#include "gssm/models/nav2d.h"
#include "gssm/models/radar2d.h"
#include "gssm/models/strapdown_ins.h"
#include "gssm/model/simulation.h"
#include "reference_kalman.h"
#include "simulated_drive.h"

using namespace gssm;

namespace {

struct Event {
  double t;
  bool is_input;
  Eigen::VectorXd v;
  int channel = 0;
};

// Inputs and measurements in time order (an input first at equal times).
std::vector<Event> eventsOf(const std::vector<Input>& inputs, const std::vector<Measurement>& measurements) {
  std::vector<Event> ev;
  for (const auto& u : inputs) ev.push_back({u.t, true, u.u});
  for (const auto& m : measurements) ev.push_back({m.t, false, m.y, m.channel});
  std::stable_sort(ev.begin(), ev.end(), [](const Event& a, const Event& b) {
    return a.t < b.t || (a.t == b.t && a.is_input && !b.is_input);
  });
  return ev;
}
std::vector<Event> eventsOf(const SimulatedRun& run) { return eventsOf(run.inputs, run.measurements); }

void apply(Estimator& e, const Event& ev) {
  if (ev.is_input) e.addInput(ev.t, ev.v);
  else e.addMeasurement(Measurement{ev.t, ev.v, ev.channel, {}});
}

// What a user reads after each event, as raw bits (NaN-safe comparison).
std::string observe(Estimator& e) {
  std::string bits;
  auto put = [&](const double* p, std::size_t n) { bits.append(reinterpret_cast<const char*>(p), n * sizeof(double)); };
  const StateEstimate s = e.current();
  put(s.mean.data(), static_cast<std::size_t>(s.mean.size()));
  put(s.covariance.data(), static_cast<std::size_t>(s.covariance.size()));
  if (auto older = e.smoothed(std::max<std::int64_t>(0, e.step() - 2))) put(older->mean.data(), static_cast<std::size_t>(older->mean.size()));
  const double nis = e.report().nis;
  put(&nis, 1);
  const double t = e.time();
  put(&t, 1);
  return bits;
}

void expectBitIdenticalContinuation(const Model& model, const EstimatorOptions& o,
                                    const std::vector<Event>& events, const std::vector<std::size_t>& cuts) {
  for (std::size_t cut : cuts) ASSERT_LE(cut, events.size());
  auto full = makeEstimator(model, o);
  std::vector<std::string> trace;
  for (const auto& ev : events) {
    apply(*full, ev);
    trace.push_back(observe(*full));
  }
  for (std::size_t cut : cuts) {
    const std::string what = std::string(methodName(o.method)) + " restored after event " + std::to_string(cut);
    auto first = makeEstimator(model, o);
    for (std::size_t i = 0; i < cut; ++i) {
      apply(*first, events[i]);
      observe(*first);  // same reads as the full run: reads refresh lazy estimates
    }
    const std::string bytes = checkpointBytes(*first, "rows=" + std::to_string(cut));
    CheckpointInfo info;
    auto resumed = restoreCheckpointBytes(model, bytes, "test", &info);
    EXPECT_EQ(info.method, o.method) << what;
    EXPECT_EQ(info.model, model.name()) << what;
    EXPECT_EQ(info.step, first->step()) << what;
    EXPECT_EQ(info.user_data, "rows=" + std::to_string(cut)) << what;
    EXPECT_EQ(info.version, kCheckpointVersion) << what;
    EXPECT_TRUE(checkpointBytes(*resumed, info.user_data) == bytes) << what << ": a restored estimator saves the same bytes";
    if (cut > 0) {  // read right away (a copy: a read may refresh lazy estimates), it says what the run said
      auto probe = restoreCheckpointBytes(model, bytes, "test");
      EXPECT_TRUE(observe(*probe) == trace[cut - 1]) << what << ": reads differently right after the restore";
    }
    for (std::size_t i = cut; i < events.size(); ++i) {
      apply(*resumed, events[i]);
      ASSERT_TRUE(observe(*resumed) == trace[i]) << what << ": differs at event " << i;
    }
  }
}

SimulatedRun radarRun(int steps, unsigned seed) {
  SimulationSpec spec;
  spec.steps = steps;
  return simulate(models::Radar2D(), spec, gssm::testing::normalSampler(seed));
}

}  // namespace

TEST(Checkpoint, EveryMethodContinuesBitIdenticallyOnTheRadar) {
  const models::Radar2D radar;
  const auto events = eventsOf(radarRun(60, 5));
  for (const auto& method : streamingMethods()) {
    EstimatorOptions o;
    o.method = method;
    o.fixed_lag.window = o.paper_window.window = 10;
    // 0: fresh; 1 and 5: inside the nonlinear start-up; 30: window full.
    expectBitIdenticalContinuation(radar, o, events, {0, 1, 5, 30});
  }
}

TEST(Checkpoint, IteratedIncrementalAndNisContinueBitIdentically) {
  const models::Radar2D radar;
  const auto events = eventsOf(radarRun(20, 6));
  EstimatorOptions o;
  o.method = Method::Incremental;
  o.compute_nis = true;
  o.smoother.iterate_to_convergence = true;
  o.smoother.max_iterations = 200;
  o.smoother.newton_polish_steps = 3;
  expectBitIdenticalContinuation(radar, o, events, {3, 12});
}

TEST(Checkpoint, MultiRateWithInputsContinuesBitIdentically) {
  const models::Nav2D nav;
  SimulationSpec spec;
  spec.steps = 60;
  spec.measure_every = 3;
  spec.input = [](double t, const Eigen::VectorXd& xb) {
    Eigen::VectorXd u(2);
    u << 0.5 * std::cos(0.2 * t) + xb[0], 0.5 * std::sin(0.2 * t) + xb[1];
    return u;
  };
  const auto events = eventsOf(simulate(nav, spec, gssm::testing::normalSampler(7)));
  for (const Method method : {Method::Ekf, Method::Incremental, Method::FixedLag}) {
    EstimatorOptions o;
    o.method = method;
    o.fixed_lag.window = o.paper_window.window = 7;
    o.compute_nis = true;
    o.ekf.constant_process_noise = Eigen::VectorXd::Constant(3, 1e-8);
    ASSERT_EQ(events.size(), 80u);
    expectBitIdenticalContinuation(nav, o, events, {2, 41, 70});
  }
}

TEST(Checkpoint, LinearModelWithoutConstantsContinuesBitIdentically) {
  std::mt19937 rng(3);
  const models::LinearModel model(gssm::testing::randomLinearSystem(rng, 3, 0, 2, 0.1));
  SimulationSpec spec;
  spec.steps = 30;
  const auto events = eventsOf(simulate(model, spec, gssm::testing::normalSampler(4)));
  for (const auto& method : streamingMethods()) {
    EstimatorOptions o;
    o.method = method;
    o.fixed_lag.window = o.paper_window.window = 4;
    expectBitIdenticalContinuation(model, o, events, {2, 17});
  }
}

namespace {
// A fixed-lag checkpoint of a radar run (window full, marginal prior present).
std::string radarCheckpoint(Method method = Method::FixedLag) {
  const models::Radar2D radar;
  EstimatorOptions o;
  o.method = method;
  o.fixed_lag.window = o.paper_window.window = 5;
  auto est = makeEstimator(radar, o);
  for (const auto& m : radarRun(25, 9).measurements) est->addMeasurement(m.t, m.y);
  return checkpointBytes(*est, "progress");
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const CheckpointError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("WRONG EXCEPTION TYPE: ") + e.what();
  }
  return "NO ERROR";
}

// Replaces the payload checksum, so a corrupted payload reaches the parser.
std::string withValidChecksum(std::string bytes) {
  const std::uint64_t h = internal::fnv1a64(bytes.data() + 28, bytes.size() - 28);
  std::memcpy(&bytes[20], &h, sizeof h);
  return bytes;
}
}  // namespace

TEST(Checkpoint, EveryTruncationIsRejectedAndSaysSo) {
  const models::Radar2D radar;
  const std::string bytes = radarCheckpoint();
  ASSERT_NO_THROW(restoreCheckpointBytes(radar, bytes));
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    const std::string msg = errorOf([&] { restoreCheckpointBytes(radar, bytes.substr(0, n), "run.ckpt"); });
    ASSERT_NE(msg.find("run.ckpt"), std::string::npos) << n << ": " << msg;
    const bool says = msg.find(n < 8 ? "not a gssm checkpoint" : "truncated") != std::string::npos;
    ASSERT_TRUE(says) << "length " << n << ": " << msg;
  }
  EXPECT_NE(errorOf([&] { restoreCheckpointBytes(radar, bytes + "x"); }).find("trailing bytes"), std::string::npos);
}

TEST(Checkpoint, EveryCorruptedByteIsRejected) {
  const models::Radar2D radar;
  const std::string bytes = radarCheckpoint();
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::string bad = bytes;
    bad[i] = static_cast<char>(bad[i] ^ 0x5a);
    const std::string msg = errorOf([&] { restoreCheckpointBytes(radar, bad, "run.ckpt"); });
    const char* expected = i < 8 ? "not a gssm checkpoint" : i < 12 ? "format version" : i < 20 ? "payload bytes" : "checksum";
    ASSERT_NE(msg.find(expected), std::string::npos) << "byte " << i << ": " << msg;
  }
}

TEST(Checkpoint, PayloadCorruptionBehindAValidChecksumIsCaughtOrHarmless) {
  // What a fuzzer does, deterministically: every payload byte flipped, the
  // checksum fixed. Restore either rejects it with a CheckpointError or
  // yields an estimator that can be read and stepped without crashing.
  const models::Radar2D radar;
  const auto more = radarRun(27, 9).measurements;
  for (const Method method : {Method::FixedLag, Method::PaperWindow, Method::Ekf}) {
    const std::string bytes = radarCheckpoint(method);
    int rejected = 0, accepted = 0;
    for (std::size_t i = 28; i < bytes.size(); ++i) {
      std::string bad = bytes;
      bad[i] = static_cast<char>(bad[i] ^ 0x41);
      try {
        auto est = restoreCheckpointBytes(radar, withValidChecksum(bad));
        ++accepted;
        try {
          est->current();
          est->addMeasurement(more[25].t, more[25].y);
          est->current();
        } catch (const Error&) {
        }
      } catch (const CheckpointError& e) {
        ++rejected;
        ASSERT_NE(std::string(e.what()).find("byte "), std::string::npos) << e.what();
      }
    }
    EXPECT_GT(rejected, 0) << method;
    EXPECT_GT(accepted, 0) << method << " (flipped value bits are still valid numbers)";
  }
}

TEST(Checkpoint, ForeignModelVersionAndFileErrorsNameTheCause) {
  const models::Radar2D radar;
  const std::string bytes = radarCheckpoint();
  std::mt19937 rng(1);
  const models::LinearModel linear(gssm::testing::randomLinearSystem(rng, 2, 2, 1, 1.0));
  EXPECT_NE(errorOf([&] { restoreCheckpointBytes(linear, bytes); }).find("written by model 'radar_2d'"), std::string::npos);
  models::Radar2D::Params p;
  p.r *= 2;
  const models::Radar2D other(p);
  EXPECT_NE(errorOf([&] { restoreCheckpointBytes(other, bytes); }).find("other noise or prior"), std::string::npos);
  std::string newer = bytes;
  newer[8] = static_cast<char>(kCheckpointVersion + 1);  // a newer format than this build reads
  EXPECT_NE(errorOf([&] { restoreCheckpointBytes(radar, newer); })
                .find("format version " + std::to_string(kCheckpointVersion + 1) + ", this build reads versions 1 to " +
                      std::to_string(kCheckpointVersion)),
            std::string::npos);
  EXPECT_NE(errorOf([&] { restoreCheckpoint(radar, "/nonexistent/run.ckpt"); }).find("cannot open checkpoint '/nonexistent/run.ckpt'"), std::string::npos);
  EXPECT_NE(errorOf([&] { restoreCheckpointBytes(radar, "GSSMCKPT"); }).find("truncated while reading format version"), std::string::npos);
}

TEST(Checkpoint, SavesAtomicallyToAFileAndRestores) {
  const models::Radar2D radar;
  EstimatorOptions o;
  auto est = makeEstimator(radar, o);
  const auto ms = radarRun(12, 2).measurements;
  for (int k = 0; k < 10; ++k) est->addMeasurement(ms[k].t, ms[k].y);
  const std::string path = ::testing::TempDir() + "gssm_checkpoint_test.ckpt";
  saveCheckpoint(*est, path, "ten rows");
  std::ifstream tmp(path + ".tmp");
  EXPECT_FALSE(tmp.good()) << "the temporary file is renamed over the checkpoint";
  CheckpointInfo info;
  auto again = restoreCheckpoint(radar, path, &info);
  EXPECT_EQ(info.user_data, "ten rows");
  EXPECT_EQ(info.step, 10);
  EXPECT_EQ(info.time, est->time());
  EXPECT_EQ(again->current().mean, est->current().mean);
  std::remove(path.c_str());
}

TEST(Checkpoint, CommittedVersionOneFilesStillRestore) {
  // The fuzzer's seeds are checkpoints written by this format version; if a
  // change breaks reading them, bump kCheckpointVersion and regenerate them.
  const models::Radar2D radar;
  for (const auto& method : streamingMethods()) {
    const std::string path = std::string(GSSM_SOURCE_DIR) + "/tests/fuzz/corpus/checkpoint/radar-" + methodName(method) + ".ckpt";
    CheckpointInfo info;
    auto est = restoreCheckpoint(radar, path, &info);
    EXPECT_EQ(info.method, method);
    EXPECT_EQ(info.step, 6);
    EXPECT_EQ(info.user_data, "seed");
    EXPECT_TRUE(est->current().mean.allFinite()) << method;
  }
}

TEST(Checkpoint, ASlotWithAnEmptyLinearizationIsRefusedByName) {
  // Found by the checkpoint fuzzer (header repaired): a live factor slot
  // whose linearization is on no variable left the slot without a record,
  // and storing it read a record that did not exist.
  const models::Radar2D radar;
  std::ifstream f(std::string(GSSM_SOURCE_DIR) + "/tests/fuzz/corpus/checkpoint/regression-empty-slot-linearization.ckpt",
                  std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 28u);
  const std::string msg = errorOf([&] { restoreCheckpointBytes(radar, withValidChecksum(bytes), "fuzz.ckpt"); });
  EXPECT_NE(msg.find("linearization is on no variable"), std::string::npos) << msg;
}

TEST(Checkpoint, OptionsThatWouldStallAnUpdateAreRefused) {
  // Found by the checkpoint fuzzer: a checkpoint (header repaired) whose
  // options asked for 4194307 relinearization rounds per update restored
  // fine and then ran for minutes. Options now have upper bounds.
  const models::Radar2D radar;
  std::ifstream f(std::string(GSSM_SOURCE_DIR) + "/tests/fuzz/corpus/checkpoint/regression-huge-local-iterations.ckpt",
                  std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 28u);
  const std::string msg = errorOf([&] { restoreCheckpointBytes(radar, withValidChecksum(bytes), "fuzz.ckpt"); });
  EXPECT_NE(msg.find("max_local_iterations must be in [0, 100], got 4194307"), std::string::npos) << msg;
  SmootherOptions o;
  o.max_iterations = 100001;
  std::string why;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("max_iterations"), std::string::npos) << why;
}

// A model with a rotation block (issue #37): the strapdown INS on a short
// simulated drive (standing, then pulling away), every method.
TEST(Checkpoint, EveryMethodContinuesBitIdenticallyOnTheStrapdownIns) {
  models::StrapdownIns::Params p;
  p.T = 0.05;
  p.anchor = {0.7, -1.8, 1600.0};
  p.mount_rpy = Eigen::Vector3d(M_PI, 0.0, M_PI);
  p.start_rpy = gssm::testing::driveStartRpy(p.mount_rpy);
  p.attitude_sd = 0.05, p.mount_sd = 0.05, p.gyro_bias_sd = 2e-3, p.accel_bias_sd = 0.05;
  const models::StrapdownIns ins(p);
  const auto drive = gssm::testing::simulateDrive(ins, 7.0, gssm::testing::normalSampler(8));
  const auto events = eventsOf(drive.inputs, drive.measurements);
  for (const auto& method : streamingMethods()) {
    EstimatorOptions o;
    o.method = method;
    o.fixed_lag.window = o.paper_window.window = 10;
    expectBitIdenticalContinuation(ins, o, events, {0, 60, 150});
  }
}
