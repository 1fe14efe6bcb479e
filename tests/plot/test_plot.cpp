#include <gtest/gtest.h>
#include <mrpt/img/CImage.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/io/ini.h"
#include "gssm/io/number_text.h"
#include "gssm/models/radar2d.h"
#include "gssm/plot/figure.h"
#include "gssm/plot/run_figures.h"
#include "gssm/plot/ticks.h"

using namespace gssm::plot;

TEST(Ticks, RoundNumbersCoveringTheRange) {
  struct Case {
    double lo, hi;
  };
  for (const Case c : {Case{0, 20}, Case{-47.3, 212.9}, Case{995.2, 1025.4}, Case{0.0012, 0.0093},
                       Case{-3e6, 7e6}, Case{5, 5}, Case{-0.5, 0.49}}) {
    const Ticks t = niceTicks(c.lo, c.hi, 8);
    ASSERT_GE(t.values.size(), 2u);
    EXPECT_LE(t.values.size(), 8u) << c.lo << " " << c.hi;
    EXPECT_LE(t.lo, c.lo);
    EXPECT_GE(t.hi, c.hi);
    // step is 1, 2, 2.5 or 5 times a power of ten
    const double mant = t.step / std::pow(10.0, std::floor(std::log10(t.step)));
    EXPECT_TRUE(std::abs(mant - 1) < 1e-9 || std::abs(mant - 2) < 1e-9 || std::abs(mant - 2.5) < 1e-9 ||
                std::abs(mant - 5) < 1e-9)
        << "step " << t.step;
    for (double v : t.values) EXPECT_NEAR(v / t.step, std::round(v / t.step), 1e-9) << v;
    // the range is not wildly larger than the data
    if (c.hi > c.lo) {
      EXPECT_LT(t.hi - t.lo, 3 * (c.hi - c.lo));
    }
  }
  EXPECT_EQ(niceTicks(0, 20, 9).step, 2.5);
  EXPECT_EQ(formatTick(2.5, 2.5), "2.5");
  EXPECT_EQ(formatTick(1000, 5), "1000");
  EXPECT_EQ(formatTick(0.05, 0.05), "0.05");
  EXPECT_EQ(formatTick(0, 0.5), "0.0");
  // Large values keep the digits that tell ticks apart (GPS seconds), small
  // steps on them too; a large step on a large value stays short.
  EXPECT_EQ(formatTick(1436038500, 50), "1436038500");
  EXPECT_NE(formatTick(1436038500, 50), formatTick(1436038550, 50));
  EXPECT_EQ(formatTick(2e6, 1e6), "2e+06");
  EXPECT_EQ(formatTick(5e-5, 1e-5), "5e-05");
}

TEST(Figure, WritesAPngOfTheRequestedSizeThatIsNotBlank) {
  Figure f;
  f.title = "test";
  f.xlabel = "t";
  f.ylabel = "y";
  Series s{"sin", {}, {}, paletteColor(0), 2, false};
  Band b{{}, {}, {}, paletteColor(0), 0.2};
  for (int i = 0; i <= 100; ++i) {
    const double x = i * 0.1, y = std::sin(x);
    s.x.push_back(x);
    s.y.push_back(y);
    b.x.push_back(x);
    b.lo.push_back(y - 0.2);
    b.hi.push_back(y + 0.2);
  }
  s.y[0] = 1e6;  // a first-step outlier must not squash the rest
  f.series.push_back(s);
  f.bands.push_back(b);
  const std::string path = (std::filesystem::temp_directory_path() / "gssm_plot_test.png").string();
  savePng(f, path, 640, 400);
  mrpt::img::CImage img;
  ASSERT_TRUE(img.loadFromFile(path));
  EXPECT_EQ(img.getWidth(), 640u);
  EXPECT_EQ(img.getHeight(), 400u);
  // Count pixels of the series colour (the curve), and non-white pixels.
  std::size_t curve = 0, ink = 0;
  const Color c = paletteColor(0);
  for (unsigned y = 0; y < 400; ++y)
    for (unsigned x = 0; x < 640; ++x) {
      const uint8_t* p = img.ptr<uint8_t>(x, y);
      if (p[0] != 255 || p[1] != 255 || p[2] != 255) ++ink;
      if (p[2] == c.r && p[1] == c.g && p[0] == c.b) ++curve;
    }
  EXPECT_GT(ink, 640u * 400u / 50);
  // the sine spans most of the plot height: its curve has many pixels, which
  // it would not if the 1e6 outlier had set the range
  EXPECT_GT(curve, 800u);
}

TEST(Figure, FiguresDrawnInParallelAreTheFilesDrawnOneAfterAnother) {
  // Eight figures of different curves (and one path that cannot be
  // written), drawn by one thread and by three: the same bytes, and the
  // error still reported once every other figure was written.
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() / "gssm_plot_parallel";
  fs::remove_all(root);
  std::vector<std::pair<Figure, std::string>> one, three;
  for (int k = 0; k < 8; ++k) {
    Figure f;
    f.title = "curve " + std::to_string(k);
    Series s{"s", {}, {}, paletteColor(k), 2, false};
    for (int i = 0; i <= 200; ++i) {
      s.x.push_back(i * 0.05);
      s.y.push_back(std::sin((k + 1) * i * 0.05));
    }
    f.series.push_back(s);
    for (auto* jobs : {&one, &three}) {
      const fs::path dir = root / (jobs == &one ? "one" : "three");
      fs::create_directories(dir);
      jobs->emplace_back(f, (dir / ("fig-" + std::to_string(k) + ".png")).string());
    }
  }
  savePngs(one, 1);
  three.emplace(three.begin() + 3, one[0].first, (root / "missing-dir" / "x.png").string());
  EXPECT_THROW(savePngs(three, 3), std::runtime_error);
  for (int k = 0; k < 8; ++k) {
    auto bytes = [](const std::string& p) {
      std::ifstream in(p, std::ios::binary);
      return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    };
    const std::string a = bytes(one[static_cast<std::size_t>(k)].second);
    EXPECT_FALSE(a.empty()) << k;
    EXPECT_EQ(a, bytes((root / "three" / ("fig-" + std::to_string(k) + ".png")).string())) << k;
  }
  fs::remove_all(root);
}

// A constant's figure draws its band at ±k σ of each row ([scenario]
// band_sigmas; 3 by default), the width named in the title; a width that is
// not a positive number is refused, naming the file and key.
TEST(RunFigures, AConstantsBandIsAsWideAsAsked) {
  const gssm::models::Radar2D model{gssm::models::Radar2D::Params{}};
  gssm::OfflineRun run;
  run.method = gssm::Method::Batch;
  for (int r = 0; r < 5; ++r) {
    gssm::EstimateRow row;
    row.t = r;
    row.mean = Eigen::VectorXd::Constant(3, 1.0 + r);
    row.covariance = Eigen::MatrixXd::Identity(3, 3) * (0.25 + r);
    run.rows.push_back(row);
  }
  const std::vector<gssm::OfflineRun> runs{run};
  for (double k : {3.0, 2.0}) {
    const auto jobs = runFigureJobs(model, runs, nullptr, "/tmp", "test", std::nullopt, k);
    const auto constant = std::find_if(jobs.begin(), jobs.end(), [](const FigureJob& j) {
      return j.path.find("fig-h.png") != std::string::npos;
    });
    ASSERT_NE(constant, jobs.end());
    const Figure f = constant->make();
    EXPECT_NE(f.title.find(gssm::io::formatDouble(k) + "-sigma band"), std::string::npos) << f.title;
    ASSERT_EQ(f.bands.size(), 1u);
    for (std::size_t r = 0; r < 5; ++r)
      EXPECT_NEAR(f.bands[0].hi[r] - f.bands[0].lo[r], 2 * k * std::sqrt(0.25 + static_cast<double>(r)), 1e-12);
  }
  const auto ini = gssm::io::IniDocument::parse("[scenario]\nband_sigmas = 0\n", "bands.ini");
  EXPECT_THROW(
      try { gssm::io::figureBandSigmas(ini); } catch (const gssm::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("bands.ini:2"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("band_sigmas"), std::string::npos) << e.what();
        throw;
      },
      gssm::InputError);
  EXPECT_EQ(gssm::io::figureBandSigmas(gssm::io::IniDocument::parse("[scenario]\n", "none.ini")), 3.0);
}
