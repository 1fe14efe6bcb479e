// Bad input on the GNSS/INS drive (issue #37): each fault in a copy of the
// drive's files is named by file, line and column when the scenario is read
// (the model's start from data and the dataset reader alike), before
// anything is estimated.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "expect_error.h"
#include "gssm/io/config.h"
#include "gssm/io/dataset.h"

namespace gssm {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> linesOf(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

void writeLines(const fs::path& p, const std::vector<std::string>& lines) {
  std::ofstream out(p);
  for (const auto& l : lines) out << l << "\n";
}

// A copy of the drive with `edit` applied to the named file's lines.
fs::path corrupted(const std::string& name, const std::string& file,
                   const std::function<void(std::vector<std::string>&)>& edit) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("drive-" + name);
  fs::remove_all(dir);
  fs::copy(GSSM_SOURCE_DIR "/datasets/gnss-ins-drive", dir);
  std::vector<std::string> lines = linesOf(dir / file);
  edit(lines);
  writeLines(dir / file, lines);
  return dir;
}

// Reads the scenario as gssm-process does: the model (its start from the
// log), then the dataset.
void readDrive(const fs::path& dir) {
  const io::IniDocument ini = io::readScenario(dir.string());
  const auto model = io::makeModel(ini, dir.string());
  io::Dataset d;
  io::readDatasetData(dir.string(), *model, d, io::BadRows::Throw, &ini);
}

TEST(DriveBadInput, ImuGoingBackInTimeIsNamed) {
  const fs::path dir = corrupted("back", "imu.csv", [](auto& l) { std::swap(l[5001], l[5002]); });
  testing::expectThrowsNaming<InputError>([&] { readDrive(dir); }, {"imu.csv:5003", "column 't'", "before the previous"});
}

TEST(DriveBadInput, ImuNanIsNamed) {
  const fs::path dir = corrupted("nan", "imu.csv", [](auto& l) { l[7000] = "1436038531.8,0.1,0.2,nan,0.1,0.2,9.8"; });
  testing::expectThrowsNaming<InputError>([&] { readDrive(dir); }, {"imu.csv:7001", "column 'gz'", "not a finite"});
}

TEST(DriveBadInput, ImuMissingColumnIsNamed) {
  const fs::path dir = corrupted("column", "imu.csv", [](auto& l) {
    for (auto& line : l) line = line.substr(0, line.rfind(','));  // az gone
  });
  testing::expectThrowsNaming<InputError>([&] { readDrive(dir); }, {"imu.csv:1", "az"});
}

TEST(DriveBadInput, PosInAnotherLayoutIsRefusedWithTheOptionToChange) {
  const fs::path dir = corrupted("xyz", "gnss.pos", [](auto& l) {
    const std::string from = "latitude(deg) longitude(deg) height(m)";
    l[0].replace(l[0].find(from), from.size(), "x-ecef(m)      y-ecef(m)      z-ecef(m)");
  });
  testing::expectThrowsNaming<InputError>([&] { readDrive(dir); }, {"gnss.pos:2", "x-ecef(m)", "Lat/Lon/Height"});
}

// A log whose outage rows were taken out of its .pos before gssm sees it
// may come without outages.csv: nothing is withheld, and the run says so.
TEST(DriveBadInput, WithoutItsOutagesFileNothingIsWithheldAndItSaysSo) {
  const fs::path dir = corrupted("no-outages", "outages.csv", [](auto&) {});
  fs::remove(dir / "outages.csv");
  const io::IniDocument ini = io::readScenario(dir.string());
  const auto model = io::makeModel(ini, dir.string());
  io::Dataset d;
  io::readDatasetData(dir.string(), *model, d, io::BadRows::Throw, &ini);
  EXPECT_TRUE(d.withheld.empty());
  const auto fixes = std::count_if(d.measurements.begin(), d.measurements.end(),
                                   [&](const Measurement& m) { return m.channel == model->channelIndex("gnss"); });
  EXPECT_EQ(fixes, 1090 - 14);  // every RTK-fixed fix after the start is used
  EXPECT_EQ(d.gnss_dropped, 8u);  // the float ones, by gnss_max_quality
  EXPECT_TRUE(std::any_of(d.dropped.begin(), d.dropped.end(),
                          [](const std::string& m) { return m.find("outages.csv: no such file") != std::string::npos; }));
}

TEST(DriveBadInput, GnssBeforeTheFirstImuRowIsDroppedAndNamed) {
  const fs::path dir = fs::path(GSSM_SOURCE_DIR "/datasets/gnss-ins-drive");
  const io::IniDocument ini = io::readScenario(dir.string());
  const auto model = io::makeModel(ini, dir.string());
  io::Dataset d;
  io::readDatasetData(dir.string(), *model, d, io::BadRows::Throw, &ini);
  ASSERT_EQ(d.dropped.size(), 14u);
  for (const auto& message : d.dropped) EXPECT_NE(message.find("gnss.pos:"), std::string::npos) << message;
  EXPECT_GT(d.measurements.front().t, d.inputs.front().t);
}

}  // namespace
}  // namespace gssm
