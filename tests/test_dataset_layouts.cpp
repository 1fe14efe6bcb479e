// The [dataset] options a log of several tags and anchors needs: a channel
// named by two columns (tag, anchor), the truth's yaw from a quaternion and
// interpolated to the measurement times, start_time = first, a non-physical
// value dropped and listed, one row per epoch; bad rows named by file:line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <algorithm>
#include <iomanip>

#include "gssm/analysis/metrics.h"
#include "gssm/analysis/offline.h"
#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/io/dataset.h"

using namespace gssm;
namespace fs = std::filesystem;

namespace {
const char* kIni =
    "[model]\ntype = planar_rigid_body\nT = 0.01\nanchors = [0 -3 3 1; 1 3 3 1; 2 0 -3 1]\n"
    "tags = [0 -0.1 0 0; 1 0.1 0 0]\nheight = 1\n"
    "[dataset]\nmeasurements = ranges.csv\nmeasurement_columns = range\nchannel_column = tag anchor\n"
    "channel_prefix = range_\ndrop_at_or_below = 0\ntruth = truth.csv\n"
    "truth_columns = px=x py=y yaw=yaw(qw,qx,qy,qz)\ntruth_interpolate = true\nstart_time = first\nrows = epochs\n";

std::string writeLog(const std::string& name, const std::string& ranges) {
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  fs::create_directories(dir);
  std::ofstream(dir / "scenario.ini") << kIni;
  std::ofstream(dir / "ranges.csv") << ranges;
  // Yaw 0.2 rad at t = 0 and 0.4 rad at t = 1 (quaternion about z, scalar first).
  std::ofstream truth(dir / "truth.csv");
  truth.precision(17);
  truth << "t,x,y,z,qw,qx,qy,qz\n"
                                   << "0,1,2,1," << std::cos(0.1) << ",0,0," << std::sin(0.1) << "\n"
                                   << "1,2,4,1," << std::cos(0.2) << ",0,0," << std::sin(0.2) << "\n";
  return dir.string();
}

io::Dataset read(const std::string& dir, io::BadRows bad = io::BadRows::Throw) {
  const io::IniDocument ini = io::readScenario(dir);
  const auto model = io::makeModel(ini, dir);
  io::Dataset d;
  io::readDatasetData(dir, *model, d, bad, &ini);
  return d;
}
}  // namespace

TEST(DatasetLayouts, LinksNamedByTwoColumnsAndTruthYawInterpolated) {
  const std::string dir = writeLog("uwb_layout",
                                   "t,tag,anchor,range\n0.25,0,0,4.1\n0.25,1,2,3.9\n0.25,0,1,0\n0.5,1,1,2.5\n");
  const io::Dataset d = read(dir);
  ASSERT_EQ(d.measurements.size(), 3u);  // the range of 0 dropped
  const auto model = io::makeModel(io::readScenario(dir), dir);
  EXPECT_EQ(model->channel(d.measurements[0].channel).name, "range_0_0");
  EXPECT_EQ(model->channel(d.measurements[1].channel).name, "range_1_2");
  EXPECT_EQ(model->channel(d.measurements[2].channel).name, "range_1_1");
  EXPECT_EQ(d.measurements[2].y[0], 2.5);
  ASSERT_EQ(d.dropped.size(), 1u);
  EXPECT_NE(d.dropped[0].find("ranges.csv:4"), std::string::npos) << d.dropped[0];
  EXPECT_DOUBLE_EQ(d.t0, 0.25 - 0.01);  // start_time = first: one nominal step before
  EXPECT_EQ(d.rows, RowTimes::Epochs);
  // The truth at the two epochs (0.25, 0.5), linear in position and yaw.
  ASSERT_TRUE(d.truth);
  ASSERT_EQ(d.truth->times.size(), 2u);
  EXPECT_EQ(d.truth->components, (std::vector<int>{0, 1, 2}));
  EXPECT_NEAR(d.truth->states[0][0], 1.25, 1e-12);
  EXPECT_NEAR(d.truth->states[1][1], 3.0, 1e-12);
  EXPECT_NEAR(d.truth->states[0][2], 0.25, 1e-12);
  EXPECT_NEAR(d.truth->states[1][2], 0.3, 1e-12);
}

TEST(DatasetLayouts, AnUnknownLinkIsNamedByFileLineAndColumns) {
  const std::string dir = writeLog("uwb_bad_link", "t,tag,anchor,range\n0.25,0,0,4.1\n0.3,5,0,3.9\n");
  try {
    read(dir);
    FAIL() << "an unknown tag was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("ranges.csv:3: columns 'tag, anchor': '5, 0' names channel 'range_5_0'"), std::string::npos)
        << msg;
  }
  const io::Dataset partial = read(dir, io::BadRows::Stop);  // what came before is kept
  EXPECT_EQ(partial.measurements.size(), 1u);
  ASSERT_EQ(partial.row_errors.size(), 1u);
}

TEST(DatasetLayouts, EpochRowsOfAStreamingRunAreTheBatchRows) {
  const std::string dir = writeLog("uwb_epochs",
                                   "t,tag,anchor,range\n0.25,0,0,4.1\n0.25,1,2,3.9\n0.25,0,1,3.2\n0.5,1,1,2.5\n"
                                   "0.5,0,2,4.4\n0.75,1,0,4.0\n");
  const io::Dataset d = read(dir);
  const auto model = io::makeModel(io::readScenario(dir), dir);
  EstimatorOptions o(Method::Ekf);
  o.t0 = d.t0;
  const OfflineRun ekf = runOffline(*model, o, d.measurements, {}, {}, {}, d.rows);
  o.method = Method::Batch;
  const OfflineRun batch = runOffline(*model, o, d.measurements, {}, {}, {}, d.rows);
  ASSERT_EQ(ekf.rows.size(), 3u);
  ASSERT_EQ(batch.rows.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(ekf.rows[i].t, batch.rows[i].t);
  EXPECT_EQ(ekf.update_seconds.size(), 6u);  // still one update per measurement
}

namespace {
// Writes a two-beacon range log: `order` lists the rows' times as written.
std::string writeBeaconLog(const std::string& name, const std::vector<double>& times, const std::string& extra = "") {
  const fs::path dir = fs::path(::testing::TempDir()) / name;
  fs::create_directories(dir);
  std::ofstream(dir / "scenario.ini")
      << "[model]\ntype = range_beacon_2d\nbeacons = [0 0 0; 1 10 0]\nrange_scale = false\n[prior]\nstart = 5 5\n"
      << "[dataset]\nmeasurements = ranges.csv\nmeasurement_columns = range\nchannel_column = beacon\n"
      << "channel_prefix = range_\n" << extra;
  std::ofstream ranges(dir / "ranges.csv");
  ranges << "t,beacon,range\n";
  for (double t : times) ranges << t << "," << (static_cast<int>(t * 10) % 2) << "," << 7 + t << "\n";
  return dir.string();
}
}  // namespace

TEST(DatasetLayouts, RowsWrittenLateAreReadInTimeOrderAndCounted) {
  // Two blocks written late (as the Plaza radio's): 0.6-0.8 after 1.0, 1.3 after 1.5.
  const std::vector<double> written{0.1, 0.2, 0.3, 0.4, 0.5, 0.9, 1.0, 0.6, 0.7, 0.8, 1.1, 1.2, 1.4, 1.5, 1.3, 1.6};
  std::vector<double> sorted = written;
  std::sort(sorted.begin(), sorted.end());
  const io::Dataset late = read(writeBeaconLog("late_blocks", written));
  const io::Dataset inorder = read(writeBeaconLog("in_order", sorted));
  EXPECT_EQ(late.late_rows, 4u);
  EXPECT_NEAR(late.max_lateness, 1.0 - 0.6, 1e-12);
  EXPECT_EQ(inorder.late_rows, 0u);
  ASSERT_EQ(late.measurements.size(), inorder.measurements.size());
  for (std::size_t i = 0; i < late.measurements.size(); ++i) {
    EXPECT_EQ(late.measurements[i].t, inorder.measurements[i].t);
    EXPECT_EQ(late.measurements[i].channel, inorder.measurements[i].channel);
    EXPECT_EQ(late.measurements[i].y, inorder.measurements[i].y);
  }
  // Strict, by option: the first row that goes back is named, what came before kept.
  const std::string strict = writeBeaconLog("late_strict", written, "out_of_order = error\n");
  try {
    read(strict);
    FAIL() << "a row back in time was accepted with out_of_order = error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ranges.csv:9: column 't': time 0.6 is before the previous row's 1"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(read(strict, io::BadRows::Stop).measurements.size(), 7u);
}

TEST(DatasetLayouts, RowsBeforeTheStartAreDroppedAndListedButARateMayStartAtIt) {
  // start_time = 1: the range at 0.5 and the odometry increment ending at 1
  // describe the time before the run (dropped, listed); a rate row at 1 is
  // the input from the start on (kept).
  for (const std::string kind : {"increments", "rates"}) {
    const std::string dir = writeBeaconLog("before_start_" + kind, {0.5, 1.2, 1.4},
                                           "inputs = odometry.csv\ninput_columns = v w\ninput_kind = " + kind +
                                               "\nstart_time = 1\n");
    std::ofstream(fs::path(dir) / "odometry.csv") << "t,v,w\n1,0.1,0\n1.1,0.1,0\n1.3,0.1,0\n";
    const io::Dataset d = read(dir);
    ASSERT_EQ(d.measurements.size(), 2u) << kind;
    EXPECT_EQ(d.measurements.front().t, 1.2) << kind;
    const std::size_t dropped_inputs = kind == "increments" ? 1 : 0;
    ASSERT_EQ(d.dropped.size(), 1 + dropped_inputs) << kind;
    EXPECT_NE(d.dropped.back().find("ranges.csv:2: time 0.5 is not after the start 1 (dropped: before the run)"),
              std::string::npos) << d.dropped.back();
    if (kind == "increments") {
      EXPECT_NE(d.dropped.front().find("odometry.csv:2:"), std::string::npos) << d.dropped.front();
      EXPECT_EQ(d.inputs.front().t, 1.0);  // the increment over (1, 1.1], held from the start
    } else {
      EXPECT_EQ(d.inputs.front().t, 1.0);  // the rate from the start on
      EXPECT_EQ(d.inputs.size(), 3u);
    }
  }
}

// A motion-capture truth that stops before the ranges (1 s here, ranges on
// to 1.5 s): the estimates it covers are compared, the others counted as
// rows without truth — not an error, as for a truth given at every row.
TEST(DatasetLayouts, EstimatesOutsideAnInterpolatedTruthAreCountedNotCompared) {
  const std::string dir = writeLog("uwb_truth_ends",
                                   "t,tag,anchor,range\n0.25,0,0,4.1\n0.25,1,2,3.9\n0.5,1,1,2.5\n1.25,0,2,4.4\n"
                                   "1.5,1,0,4.0\n");
  const io::Dataset d = read(dir);
  ASSERT_TRUE(d.truth);
  EXPECT_FALSE(d.truth->covers_every_row);
  EXPECT_EQ(d.truth->times.size(), 2u);  // 0.25 and 0.5
  const auto model = io::makeModel(io::readScenario(dir), dir);
  EstimatorOptions o(Method::Ekf);
  o.t0 = d.t0;
  const OfflineRun run = runOffline(*model, o, d.measurements, {}, {}, {}, d.rows);
  ASSERT_EQ(run.rows.size(), 4u);
  const RunMetrics m = computeMetrics(*model, run, &*d.truth);
  EXPECT_TRUE(m.has_truth);
  EXPECT_EQ(m.rows, 2u);
  EXPECT_EQ(m.rows_without_truth, 2u);
  Truth exact = *d.truth;  // a truth meant for every row still names the first it lacks
  exact.covers_every_row = true;
  EXPECT_THROW(computeMetrics(*model, run, &exact), InvalidArgument);
}
