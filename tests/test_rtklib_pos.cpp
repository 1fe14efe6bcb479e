// RTKLIB's solution format (.pos): what RTKLIB writes is read (GPST
// calendar or week/seconds times, the velocity columns when present, the
// signed cross terms), a written solution reads back, and every layout or
// line gssm cannot use is refused naming file, line and column.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "gssm/core/error.h"
#include "gssm/io/csv.h"
#include "gssm/io/rtklib_pos.h"
#include "expect_error.h"

using namespace gssm;
using gssm::testing::expectThrowsNaming;

namespace {
// The head of the shipped drive's gnss.pos (RTKLIB's own output), one cross term made negative.
const std::string kHeader =
    "% program   : RTKLIB ver.demo5 b34k\n"
    "%\n"
    "%  GPST            latitude(deg) longitude(deg) height(m) Q         ns        sdn(m)    sde(m)    sdu(m)    "
    "sdne(m)   sdeu(m)   sdun(m)  age(s)     ratio     vn(m/s)   ve(m/s)    vu(m/s)    sdvn      sdve     sdvu       "
    "sdvne    sdveu      sdvun\n";
const std::string kLine1 =
    "2025/07/08 19:34:18.499 40.0966268 -105.1474483 1601.4740000 1.0000000 21.0000000 0.0098995 0.0098995 0.0100000 "
    "-0.0050000 0.0000000 0.0000000 0.0000000 0.0000000 0.0100000 -0.0020000 0.0090000 0.0586899 0.0586899 0.0586899 "
    "0.0000000 0.0000000 0.0000000\n";
const std::string kLine2 =
    "2025/07/08 19:34:18.749 40.0966268 -105.1474483 1601.4760000 2.0000000 21.0000000 0.0098995 0.0098995 0.0100000 "
    "0.0000000 0.0000000 0.0000000 0.0000000 0.0000000 0.0010000 0.0020000 -0.0060000 0.0558614 0.0558614 0.0558614 "
    "0.0000000 0.0000000 0.0000000\n";

}  // namespace

TEST(RtklibPos, GpsTimeOfTheCalendar) {
  // 2025-07-08 is day 16620 after 1980-01-06 (GPS week 2374).
  EXPECT_DOUBLE_EQ(io::gpsSeconds(2025, 7, 8, 19, 34, 18.499), 1436038458.499);
  EXPECT_EQ(io::gpsSeconds(1980, 1, 6, 0, 0, 0), 0.0);
  EXPECT_EQ(io::gpsSeconds(2024, 3, 1, 0, 0, 0) - io::gpsSeconds(2024, 2, 28, 0, 0, 0), 2 * 86400.0);  // leap year
  EXPECT_EQ(io::gpstCalendar(1436038458.499), "2025/07/08 19:34:18.499");
  EXPECT_EQ(io::gpstCalendar(io::gpsSeconds(1999, 12, 31, 23, 59, 59.9996)), "2000/01/01 00:00:00.000");
}

TEST(RtklibPos, ReadsWhatRtklibWrites) {
  const io::GnssSolution s = io::parseRtklibPos(kHeader + kLine1 + kLine2, "gnss.pos");
  ASSERT_EQ(s.fixes.size(), 2u);
  EXPECT_TRUE(s.has_velocity);
  const io::GnssFix& a = s.fixes[0];
  EXPECT_DOUBLE_EQ(a.t, 1436038458.499);
  EXPECT_DOUBLE_EQ(a.lat_deg, 40.0966268);
  EXPECT_DOUBLE_EQ(a.lon_deg, -105.1474483);
  EXPECT_DOUBLE_EQ(a.height, 1601.474);
  EXPECT_EQ(a.quality, 1);
  EXPECT_EQ(a.satellites, 21);
  EXPECT_EQ(a.line, 4);
  EXPECT_DOUBLE_EQ(a.cov_neu(0, 0), 0.0098995 * 0.0098995);
  EXPECT_DOUBLE_EQ(a.cov_neu(2, 2), 0.01 * 0.01);
  EXPECT_DOUBLE_EQ(a.cov_neu(0, 1), -0.005 * 0.005);  // RTKLIB's signed square root
  EXPECT_DOUBLE_EQ(a.cov_neu(1, 0), a.cov_neu(0, 1));
  ASSERT_TRUE(a.vel_neu.has_value());
  EXPECT_DOUBLE_EQ((*a.vel_neu)(2), 0.009);  // up
  EXPECT_EQ(s.fixes[1].quality, 2);
  EXPECT_DOUBLE_EQ(s.fixes[1].t - a.t, 0.25);
  // Week and seconds of week, and no velocity columns.
  const std::string tow = "%  GPST          latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   sdu(m)\n"
                          "2374 243258.499   40.096626800 -105.147448300  1601.4740   1  21   0.0099   0.0099   0.0100\r\n";
  const io::GnssSolution w = io::parseRtklibPos(tow, "tow.pos");
  EXPECT_DOUBLE_EQ(w.fixes.at(0).t, 1436038458.499);
  EXPECT_FALSE(w.has_velocity);
  EXPECT_FALSE(w.fixes[0].vel_neu.has_value());
}

TEST(RtklibPos, AWrittenSolutionReadsBack) {
  const io::GnssSolution s = io::parseRtklibPos(kHeader + kLine1 + kLine2, "gnss.pos");
  const std::string path = (std::filesystem::path(::testing::TempDir()) / "written.pos").string();
  io::writeRtklibPos(path, s);
  const io::GnssSolution back = io::readRtklibPos(path);
  ASSERT_EQ(back.fixes.size(), s.fixes.size());
  EXPECT_TRUE(back.has_velocity);
  for (std::size_t i = 0; i < s.fixes.size(); ++i) {
    EXPECT_NEAR(back.fixes[i].t, s.fixes[i].t, 1e-6);
    EXPECT_NEAR(back.fixes[i].lat_deg, s.fixes[i].lat_deg, 1e-9);
    EXPECT_NEAR(back.fixes[i].lon_deg, s.fixes[i].lon_deg, 1e-9);
    EXPECT_NEAR(back.fixes[i].height, s.fixes[i].height, 1e-4);
    EXPECT_EQ(back.fixes[i].quality, s.fixes[i].quality);
    EXPECT_LT((back.fixes[i].cov_neu - s.fixes[i].cov_neu).cwiseAbs().maxCoeff(), 1e-8);
    EXPECT_LT((*back.fixes[i].vel_neu - *s.fixes[i].vel_neu).cwiseAbs().maxCoeff(), 1e-5);
  }
}

TEST(RtklibPos, EveryUnusableInputIsNamed) {
  const auto parse = [](const std::string& text) { return [text] { io::parseRtklibPos(text, "g.pos"); }; };
  expectThrowsNaming<InputError>(parse("%  GPST   x-ecef(m)  y-ecef(m)  z-ecef(m)  Q  ns\n2025/07/08 19:34:18.499 1 2 3 1 9\n"),
                "g.pos:2 (the header before it): column 'x-ecef(m)': an ECEF x/y/z solution");
  expectThrowsNaming<InputError>(parse("%  GPST   e-baseline(m) n-baseline(m) u-baseline(m) Q ns\n2025/07/08 19:34:18.499 1 2 3 1 9\n"),
                "east/north/up baseline");
  expectThrowsNaming<InputError>(parse("%  UTC   latitude(deg) longitude(deg) height(m) Q ns sdn(m) sde(m) sdu(m)\n"
                      "2025/07/08 19:34:00.499 40 -105 1600 1 9 0.01 0.01 0.01\n"),
                "times are UTC");
  expectThrowsNaming<InputError>(parse("2025/07/08 19:34:18.499 40 -105 1600 1 9\n"), "expected the column header");
  std::string bad_lat = kLine1;
  bad_lat.replace(bad_lat.find("40.0966268"), 10, "4O.0966268");  // a letter O
  bad_lat.replace(bad_lat.find("18.499"), 6, "19.000");
  expectThrowsNaming<InputError>(parse(kHeader + kLine1 + kLine2 + bad_lat), "g.pos:6:3: latitude '4O.0966268' is not a finite number");
  expectThrowsNaming<InputError>(parse(kHeader + kLine2 + kLine1), "g.pos:5:1: time 2025/07/08 19:34:18.499 is not after");
  expectThrowsNaming<InputError>(parse(kHeader + kLine1.substr(0, 60) + "\n"), "g.pos:4: 5 fields, the column header has 24");
  std::string bad_q = kLine1;
  bad_q.replace(bad_q.find(" 1.0000000 21."), 10, " 9.0000000");
  expectThrowsNaming<InputError>(parse(kHeader + bad_q), "g.pos:4:6: Q must be 1-6");
  expectThrowsNaming<InputError>(parse(kHeader + "2025/13/08 19:34:18.499" + kLine1.substr(23)), "g.pos:4:1: date '2025/13/08'");
  expectThrowsNaming<InputError>(parse(kHeader), "g.pos: no solution lines");
  expectThrowsNaming<InputError>([] { io::readRtklibPos("/nonexistent/g.pos"); }, "/nonexistent/g.pos: cannot open");
  // A directory (an INI value cut at "//", which starts a comment) is named,
  // not read as a file whose end is at 2^63 − 1.
  const std::string dir = ::testing::TempDir();
  expectThrowsNaming<InputError>([&] { io::readRtklibPos(dir); }, dir + ": is a directory, not the file");
  expectThrowsNaming<InputError>([&] { io::readCsv(dir); }, dir + ": is a directory");
}

TEST(RtklibPos, ReadsTheDrivesSolutionFile) {
  // datasets/gnss-ins-drive/gnss.pos as RTKLIB wrote it: 1,098 epochs at 4 Hz,
  // 1,090 RTK-fixed and 8 float, velocities included.
  const io::GnssSolution s = io::readRtklibPos(std::string(GSSM_SOURCE_DIR) + "/datasets/gnss-ins-drive/gnss.pos");
  ASSERT_EQ(s.fixes.size(), 1098u);
  EXPECT_TRUE(s.has_velocity);
  int fixed = 0, floating = 0;
  for (const auto& x : s.fixes) {
    fixed += x.quality == 1;
    floating += x.quality == 2;
    EXPECT_GT(x.cov_neu(0, 0), 0);
  }
  EXPECT_EQ(fixed, 1090);
  EXPECT_EQ(floating, 8);
  EXPECT_DOUBLE_EQ(s.fixes.front().t, 1436038458.499);  // the IMU's time base (imu.csv starts at 1436038461.854)
  EXPECT_EQ(io::gpstCalendar(s.fixes.back().t), "2025/07/08 19:38:52.749");
  EXPECT_EQ(s.fixes.back().line, 1099);
  // As named columns (a data file of a model's parameters).
  const Eigen::MatrixXd c = io::solutionColumns(s, {"t", "lat", "sdu", "vu", "q"});
  ASSERT_EQ(c.rows(), 1098);
  EXPECT_EQ(c(0, 0), s.fixes.front().t);
  EXPECT_EQ(c(5, 1), s.fixes[5].lat_deg);
  EXPECT_NEAR(c(5, 2), std::sqrt(s.fixes[5].cov_neu(2, 2)), 1e-15);
  EXPECT_EQ(c(5, 3), (*s.fixes[5].vel_neu)[2]);
  EXPECT_EQ(c(5, 4), 1.0);
  expectThrowsNaming<InputError>([&] { io::solutionColumns(s, {"speed"}); }, {"gnss.pos", "'speed'", "lat"});
}
