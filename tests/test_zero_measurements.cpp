// [dataset] zero_channels at zero_rate, and zero_at_inputs (each zero at the
// input reading nearest its time, or at a measurement next to that
// reading), on the GNSS/INS drive's own files: a state starts at every
// measurement, so zeros between readings gave steps of a fraction of a
// millisecond beside the IMU's packs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "gssm/io/config.h"
#include "gssm/io/dataset.h"

namespace gssm {
namespace {

const std::string kDrive = GSSM_SOURCE_DIR "/datasets/gnss-ins-drive";

io::Dataset readDrive(bool at_inputs) {
  io::IniDocument ini = io::readScenario(kDrive);
  ini.set("dataset", "zero_at_inputs", at_inputs ? "true" : "false");
  const auto model = io::makeModel(ini, kDrive);
  io::Dataset d;
  io::readDatasetData(kDrive, *model, d, io::BadRows::Throw, &ini);
  return d;
}

// The IMU's own reading times (imu.csv's first column).
std::vector<double> readingTimes() {
  std::ifstream in(kDrive + "/imu.csv");
  std::vector<double> t;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) t.push_back(std::stod(line.substr(0, line.find(','))));
  return t;
}

// The zero measurements (value 0 on the zero channels: nhc on the drive).
std::vector<double> zeroTimes(const io::Dataset& d, int nhc) {
  std::vector<double> t;
  for (const auto& m : d.measurements)
    if (m.channel == nhc) t.push_back(m.t);
  return t;
}

double nearest(const std::vector<double>& sorted, double t) {
  const auto it = std::lower_bound(sorted.begin(), sorted.end(), t);
  double best = INFINITY;
  if (it != sorted.end()) best = *it - t;
  if (it != sorted.begin()) best = std::min(best, t - *std::prev(it));
  return best;
}

// The steps' lengths: between consecutive packed inputs (a state at each).
std::vector<double> stepLengths(const io::Dataset& d) {
  std::vector<double> dt;
  for (std::size_t i = 1; i < d.inputs.size(); ++i) dt.push_back(d.inputs[i].t - d.inputs[i - 1].t);
  return dt;
}

TEST(ZeroMeasurements, AtInputsEachSitsOnAReadingOrAMeasurementNextToIt) {
  const io::Dataset grid = readDrive(false), snapped = readDrive(true);
  const auto model = io::makeModel(io::readScenario(kDrive), kDrive);
  const int nhc = model->channelIndex("nhc");
  const std::vector<double> on_grid = zeroTimes(grid, nhc), on_inputs = zeroTimes(snapped, nhc);
  const std::vector<double> readings = readingTimes();
  std::vector<double> others;  // the measurements that are not zeros
  for (const auto& m : snapped.measurements)
    if (m.channel != nhc) others.push_back(m.t);
  // Without the option: the 10 Hz grid from t0, between readings.
  ASSERT_GT(on_grid.size(), 2600u);
  for (std::size_t k = 0; k < on_grid.size(); ++k) EXPECT_NEAR(on_grid[k], grid.t0 + 0.1 * double(k + 1), 1e-6);
  // With it: one per grid time (the IMU's readings are 8-11 ms apart, so no
  // two grid times share a reading), each on a reading or on a measurement
  // within half a reading's interval of one: at most 11 ms off its time.
  EXPECT_EQ(on_inputs.size(), on_grid.size());
  EXPECT_TRUE(std::is_sorted(on_inputs.begin(), on_inputs.end()));
  EXPECT_EQ(std::adjacent_find(on_inputs.begin(), on_inputs.end()), on_inputs.end());
  std::size_t on_measurements = 0;
  for (double t : on_inputs) {
    const double to_reading = nearest(readings, t);
    if (to_reading > 1e-9) {
      ++on_measurements;
      EXPECT_LT(nearest(others, t), 1e-9) << "zero at " << t << " is on neither a reading nor a measurement";
      EXPECT_LT(to_reading, 0.0056) << t;
    }
    EXPECT_LT(nearest(on_grid, t), 0.011) << t;
  }
  EXPECT_GT(on_measurements, 0u);
  // So far fewer steps, and almost none of a fraction of a millisecond.
  const std::vector<double> before = stepLengths(grid), after = stepLengths(snapped);
  const auto shorter = [](const std::vector<double>& dt, double s) {
    return std::count_if(dt.begin(), dt.end(), [s](double x) { return x < s; });
  };
  EXPECT_LT(double(after.size()), 0.7 * double(before.size()));
  EXPECT_GT(shorter(before, 2e-3), 300);
  EXPECT_LT(shorter(after, 2e-3), 10);
  // The other measurements are untouched.
  std::vector<double> grid_others;
  for (const auto& m : grid.measurements)
    if (m.channel != nhc) grid_others.push_back(m.t);
  EXPECT_EQ(grid_others, others);
}

}  // namespace
}  // namespace gssm
