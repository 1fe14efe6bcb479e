#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <clocale>
#include <cstdlib>
#include <random>

#include "gssm/core/error.h"
#include "expect_error.h"
#include "gssm/io/config.h"
#include "gssm/io/csv.h"
#include "gssm/io/ini.h"
#include "gssm/io/json_text.h"
#include "gssm/io/number_text.h"
#include "gssm/models/linear.h"
#include "gssm/models/radar2d.h"

using namespace gssm;
using gssm::testing::expectThrowsNaming;
using namespace gssm::io;

TEST(IniDocument, ParsesSectionsCommentsAndMatrices) {
  const auto ini = IniDocument::parse(
      "; comment\n[model]\ntype = radar2d  # trailing\nQ = [1 2; 3 4] // c\n\n[prior]\n"
      "v = 1, 2, 3\n",
      "t.ini");
  EXPECT_EQ(ini.getString("model", "type"), "radar2d");
  const Eigen::MatrixXd Q = ini.getMatrix("model", "Q", 2, 2);
  EXPECT_EQ(Q(1, 0), 3);
  EXPECT_EQ(ini.getVector("prior", "v", 3)[2], 3);
  // diagonal shorthand
  EXPECT_EQ(ini.getMatrix("prior", "v", 3, 3)(2, 2), 3);
  EXPECT_EQ(ini.getMatrix("prior", "v", 3, 3)(0, 1), 0);
}

TEST(IniDocument, ErrorsNameFileLineSectionKeyAndValue) {
  expectThrowsNaming<InputError>([] { IniDocument::parse("[a]\nx = 1\nnot a pair\n", "f.ini"); },
                   {"f.ini:3", "key = value"});
  expectThrowsNaming<InputError>([] { IniDocument::parse("x = 1\n", "f.ini"); }, {"f.ini:1", "before any"});
  expectThrowsNaming<InputError>([] { IniDocument::parse("[a]\nx = 1\nx = 2\n", "f.ini"); },
                   {"f.ini:3", "repeated", "line 2"});
  const auto ini = IniDocument::parse("[m]\nT = abc\nQ = [1 2; 3]\n", "f.ini");
  expectThrowsNaming<InputError>([&] { ini.getDouble("m", "T"); }, {"f.ini:2", "[m] T", "abc", "number"});
  expectThrowsNaming<InputError>([&] { ini.getMatrix("m", "Q"); }, {"f.ini:3", "row 2"});
  expectThrowsNaming<InputError>([&] { ini.getDouble("m", "R"); }, {"missing", "'R'", "[m]"});
}

// [<prefix>.<S>] gives one reader its own values of [S]'s keys: set over
// them (new keys added), the other sections and readers untouched, each
// overriding key's line kept for errors; a [<prefix>.<S>] whose [S] does
// not exist is refused by its line (a misspelt name would do nothing).
TEST(IniDocument, AReadersOwnSectionOverridesAnothersKeys) {
  const auto ini = IniDocument::parse(
      "[model]\nq = 1\nr = 2\n[channel.gps]\nr = 3\n[batch.model]\nq = 10\ns = 5\n[batch.channel.gps]\nr = 30\n", "f.ini");
  EXPECT_TRUE(ini.hasOverrides("batch"));
  EXPECT_FALSE(ini.hasOverrides("ekf"));
  EXPECT_FALSE(ini.hasOverrides("channel.gp"));  // a prefix is a whole name
  const IniDocument b = ini.overriddenBy("batch");
  EXPECT_EQ(b.getDouble("model", "q"), 10.0);
  EXPECT_EQ(b.getDouble("model", "r"), 2.0);
  EXPECT_EQ(b.getDouble("model", "s"), 5.0);
  EXPECT_EQ(b.getDouble("channel.gps", "r"), 30.0);
  EXPECT_EQ(b.lineOf("model", "q"), 7);
  EXPECT_EQ(ini.getDouble("model", "q"), 1.0);  // the document itself as it was
  EXPECT_EQ(ini.overriddenBy("ekf").getDouble("model", "q"), 1.0);
  expectThrowsNaming<InputError>(
      [] { IniDocument::parse("[model]\nq = 1\n[batch.modle]\nq = 2\n", "g.ini").overriddenBy("batch"); },
      {"g.ini:3", "[batch.modle]", "[modle]"});
}

TEST(IniDocument, WriteThenParseRoundTripsBits) {
  IniDocument a;
  a.set("s", "x", 0.1 + 0.2);
  Eigen::MatrixXd m(2, 2);
  m << 1.0 / 3, -2e-17, 4e100, 5;
  a.set("s", "m", m);
  const auto b = IniDocument::parse(a.toString());
  EXPECT_EQ(b.getDouble("s", "x"), 0.1 + 0.2);
  EXPECT_EQ(b.getMatrix("s", "m"), m);
}

TEST(Config, BuiltinScenarioBuildsThePaperModel) {
  const auto ini = IniDocument::parse(builtinScenario("paper", 3, 50).toString(), "p.ini");
  const auto model = makeModel(ini);
  const models::Radar2D paper;
  EXPECT_EQ(model->name(), "radar_2d");
  EXPECT_EQ(model->noise().Q, paper.noise().Q);
  EXPECT_EQ(model->priorConstants().mean, paper.priorConstants().mean);
  EXPECT_EQ(model->priorConstants().covariance, paper.priorConstants().covariance);
  const auto spec = simulationSpec(ini, *model);
  EXPECT_EQ(spec.steps, 50);
  EXPECT_FALSE(spec.process_noise);
  EXPECT_EQ((*spec.xb)[1], 1000);
  EXPECT_EQ(estimatorOptions(ini, *model).ekf.constant_process_noise[0], 0.005 * 0.005);
  EXPECT_THROW(builtinScenario("nope", 1, 1), InvalidArgument);
}

TEST(Config, BadModelConfigsNameTheProblem) {
  auto base = builtinScenario("paper", 1, 10);
  base.set("model", "type", "radar3d");
  expectThrowsNaming<InputError>([&] { makeModel(IniDocument::parse(base.toString(), "c.ini")); },
                   {"c.ini", "radar3d", "unknown model"});
  base = builtinScenario("paper", 1, 10);
  base.set("prior", "constants_cov", "[49 0; 0 -1]");
  expectThrowsNaming<InputError>([&] { makeModel(IniDocument::parse(base.toString(), "c.ini")); },
                   {"c.ini", "positive definite", "x_b"});
  base = builtinScenario("paper", 1, 10);
  base.set("model", "Qq", "1");
  expectThrowsNaming<InputError>([&] { makeModel(IniDocument::parse(base.toString(), "c.ini")); },
                   {"unknown key 'Qq'"});
}

TEST(Csv, ParsesAndReportsLineColumnValue) {
  const auto t = parseCsv("t,range\n0.05,1000\n\n0.1,1001.5\n", "m.csv");
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.line_of_row[1], 4);
  EXPECT_EQ(t.rows[1][1], 1001.5);
  expectThrowsNaming<InputError>([] { parseCsv("t,range\n0.05,abc\n", "m.csv"); },
                   {"m.csv:2", "'range'", "'abc'"});
  expectThrowsNaming<InputError>([] { parseCsv("t,range\n0.05,nan\n", "m.csv"); }, {"m.csv:2", "nan"});
  expectThrowsNaming<InputError>([] { parseCsv("t,range\n0.05\n", "m.csv"); }, {"m.csv:2", "1 fields"});
  expectThrowsNaming<InputError>([] { parseCsv("0.05,1000\n", "m.csv"); }, {"m.csv:1", "header"});
  expectThrowsNaming<InputError>([] { parseCsv("", "m.csv"); }, {"m.csv", "empty"});
}

TEST(Config, EstimatorSectionsAreReadAndChecked) {
  auto ini = builtinScenario("paper", 1, 10);
  ini.set("smoother", "ordering", "time");
  ini.set("smoother", "relinearize_threshold", 0.5);
  ini.set("fixed_lag", "window", "25");
  ini.set("smoother", "iterate_to_convergence", "true");
  ini.set("smoother", "newton_polish_steps", "4");
  ini.set("batch", "algorithm", "gauss-newton");
  ini.set("batch", "newton_polish_steps", "2");
  ini.set("batch", "initial_lambda", "1e-3");
  const auto parsed = IniDocument::parse(ini.toString(), "s.ini");
  const auto model = makeModel(parsed);
  const EstimatorOptions eo = estimatorOptions(parsed, *model);
  const SmootherOptions& o = eo.smoother;
  EXPECT_EQ(eo.incremental.ordering, EliminationOrdering::TimeOrdered);
  EXPECT_EQ(o.relinearize_threshold, 0.5);
  EXPECT_TRUE(o.iterate_to_convergence);
  EXPECT_EQ(o.newton_polish_steps, 4);
  EXPECT_EQ(eo.fixed_lag.window, 25);
  EXPECT_EQ(eo.paper_window.window, 10);
  EXPECT_EQ(eo.batch.method, BatchSolverOptions::Method::GaussNewton);
  EXPECT_EQ(eo.batch.newton_polish_steps, 2);
  EXPECT_EQ(eo.batch.initial_lambda, 1e-3);
  EXPECT_EQ(estimatorOptions(parsed, *model, Method::PaperWindow).window(), 10);
  EXPECT_EQ(estimatorOptions(parsed, *model, Method::FixedLag).window(), 25);
  ini.set("smoother", "wildfire", "1");
  expectThrowsNaming<InputError>([&] { estimatorOptions(IniDocument::parse(ini.toString(), "s.ini"), *model); },
                   {"s.ini", "unknown key 'wildfire'", "[smoother]"});
  ini = builtinScenario("paper", 1, 10);
  ini.set("fixed_lag", "window", "0");
  expectThrowsNaming<InputError>([&] { estimatorOptions(IniDocument::parse(ini.toString(), "s.ini"), *model); },
                   {"s.ini", "[fixed_lag]", "window"});
  ini = builtinScenario("paper", 1, 10);
  ini.set("batch", "algorithm", "newton");
  expectThrowsNaming<InputError>([&] { estimatorOptions(IniDocument::parse(ini.toString(), "s.ini"), *model); },
                   {"s.ini", "[batch] algorithm", "'newton'"});
}

TEST(Config, MethodNamesAreParsedAtTheEdge) {
  EXPECT_EQ(parseMethod("fixed-lag", "option --method"), Method::FixedLag);
  EXPECT_EQ(parseMethod("batch", "option --method"), Method::Batch);
  expectThrowsNaming<InputError>([] { parseMethod("kalman", "option --method"); },
                   {"option --method", "'kalman'", "ekf, batch, incremental, fixed-lag, paper-window"});
}

// The linear model's INI form holds every LinearModel: one without
// constants, and further channels as [channel.<name>] sections.
TEST(Config, LinearModelIniRoundTripsChannelsAndNoConstants) {
  models::LinearSystem sys;
  sys.A_c = (Eigen::MatrixXd(2, 2) << 0, 1, 0, 0).finished();
  sys.A_b.setZero(2, 0);
  sys.C_c = (Eigen::MatrixXd(1, 2) << 1, 0).finished();
  sys.C_b.setZero(1, 0);
  sys.noise.T = 0.1;
  sys.noise.Q = Eigen::Matrix2d::Identity() * 1e-3;
  sys.noise.R = Eigen::MatrixXd::Constant(1, 1, 0.25);
  sys.noise.prior_state = {Eigen::Vector2d(0, 1), Eigen::Matrix2d::Identity()};
  sys.noise.prior_constants = {Eigen::VectorXd(0), Eigen::MatrixXd(0, 0)};
  models::LinearChannel gps;
  gps.name = "gps";
  gps.C_c = (Eigen::MatrixXd(2, 2) << 1, 0, 0, 1).finished();
  gps.C_b.setZero(2, 0);
  gps.R = Eigen::Matrix2d::Identity() * 4;
  sys.channels.push_back(gps);
  const models::LinearModel model(sys);
  IniDocument ini;
  writeModel(model, ini);
  const auto back = makeModel(IniDocument::parse(ini.toString(), "<written>"));
  ASSERT_EQ(back->dims().nb, 0);
  ASSERT_EQ(back->numChannels(), 2);
  EXPECT_EQ(back->channel(1).name, "gps");
  EXPECT_EQ(back->channel(1).R, gps.R);
  const Eigen::Vector2d x(3, -2);
  EXPECT_EQ(back->h(1, x, Eigen::VectorXd(0)), model.h(1, x, Eigen::VectorXd(0)));
  IniDocument again;
  writeModel(*back, again);
  EXPECT_EQ(again.toString(), ini.toString());
  // a channel named without its section is named in the error
  IniDocument broken = IniDocument::parse(ini.toString(), "<broken>");
  broken.set("model", "channels", "gps wheel");
  EXPECT_THROW(
      try { makeModel(broken); } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("[channel.wheel]"), std::string::npos) << e.what();
        throw;
      },
      InputError);
}

// The fast number formatting (std::to_chars) writes exactly what the printf
// loop it replaced wrote (the shortest "%.Pg", P >= 6, that reads back), so
// files stay byte-identical; and every double reads back to its bits.
TEST(NumberText, SameTextAsThePrintfLoopAndExactRoundTrip) {
  auto printfLoop = [](double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    for (int prec = 6; prec < 17; ++prec) {
      char shorter[40];
      std::snprintf(shorter, sizeof shorter, "%.*g", prec, v);
      if (std::strtod(shorter, nullptr) == v) return std::string(shorter);
    }
    return std::string(buf);
  };
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> mantissa(-1, 1);
  std::uniform_int_distribution<int> exponent(-30, 30);
  std::vector<double> values{0.1, 1e-5, 1e-4, 1e5, 123456, 1234567, 1e21, 5e-324, 2.2250738585072014e-308,
                             1.7976931348623157e308, -0.001, 1e15, 1e16, 1e17, 9.0, 0.05, 2.5e-05};
  for (int i = 0; i < 30000; ++i) values.push_back(mantissa(rng) * std::pow(10.0, exponent(rng)));
  for (int i = 0; i < 30000; ++i) {
    const std::uint64_t bits = rng();
    double d;
    std::memcpy(&d, &bits, sizeof d);
    if (std::isfinite(d)) values.push_back(d);
  }
  int mismatches = 0;
  for (double v : values) {
    const std::string text = formatDouble(v);
    double back = 0;
    EXPECT_TRUE(parseDouble(text.data(), text.data() + text.size(), back)) << text;
    if (text != printfLoop(v) || back != v) {
      if (++mismatches < 5) ADD_FAILURE() << v << ": '" << text << "' vs printf '" << printfLoop(v) << "'";
    }
  }
  EXPECT_EQ(mismatches, 0);
  double x = 0;
  const std::string plus = "+2.5";
  EXPECT_TRUE(parseDouble(plus.data(), plus.data() + plus.size(), x) && x == 2.5);
  for (const char* bad : {"", "+", "1.5x", " 1", "0x10", "1e999"}) {
    const std::string s(bad);
    EXPECT_FALSE(parseDouble(s.data(), s.data() + s.size(), x)) << "'" << s << "'";
  }
}

TEST(Csv, WriteThenReadGivesTheSameDoubles) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01;
  std::vector<std::vector<double>> rows(2000, std::vector<double>(4));
  for (auto& r : rows)
    for (double& v : r) v = n01(rng) * std::pow(10.0, static_cast<int>(rng() % 20) - 10);
  const std::string path = ::testing::TempDir() + "/gssm_csv_roundtrip.csv";
  writeCsv(path, {"a", "b", "c", "d"}, rows);
  const CsvTable t = readCsv(path);
  ASSERT_EQ(t.rows.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    EXPECT_EQ(std::vector<double>(t.rows[i].begin(), t.rows[i].end()), rows[i]) << "row " << i;
}

TEST(JsonText, EscapesEveryControlCharacterAndKeepsUtf8) {
  EXPECT_EQ(io::jsonQuoted("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(io::jsonQuoted("\t\n\r\b\f"), "\"\\t\\n\\r\\b\\f\"");
  EXPECT_EQ(io::jsonQuoted(std::string("\x01\x1f\x7f", 3)), "\"\\u0001\\u001f\\u007f\"");
  EXPECT_EQ(io::jsonQuoted(std::string("\0", 1)), "\"\\u0000\"");
  EXPECT_EQ(io::jsonQuoted("Zürich 東京 🚗"), "\"Zürich 東京 🚗\"");  // valid UTF-8 as it is
  // Invalid UTF-8 (a lone continuation byte, a truncated sequence, an overlong '/') is replaced.
  EXPECT_EQ(io::jsonQuoted("\x80x\xe6\x9d"), "\"\\ufffdx\\ufffd\\ufffd\"");
  EXPECT_EQ(io::jsonQuoted("\xc0\xaf"), "\"\\ufffd\\ufffd\"");
}

// Run under a comma-decimal locale by the ctest entry io.IniNumbersUnderGermanLocale
// (tests/apps/german_locale.sh, GSSM_EXPECT_COMMA_LOCALE=1); alone, under the C locale.
TEST(IniLocale, NumbersParseTheSameUnderAnyLocale) {
  const char* set = std::setlocale(LC_ALL, "");
  if (std::getenv("GSSM_EXPECT_COMMA_LOCALE")) {
    ASSERT_NE(set, nullptr) << "the comma-decimal locale is not available";
    ASSERT_STREQ(std::localeconv()->decimal_point, ",") << "locale " << set;
  }
  const auto ini = IniDocument::parse("[s]\nx = 0.5\nm = [1.25 -2e-3; 3.5 4]\nbad = 0,5\n", "l.ini");
  EXPECT_EQ(ini.getDouble("s", "x"), 0.5);
  EXPECT_EQ(ini.getMatrix("s", "m")(0, 1), -2e-3);
  EXPECT_EQ(ini.getMatrix("s", "m")(1, 0), 3.5);
  EXPECT_THROW(ini.getDouble("s", "bad"), InputError);  // a comma is never a decimal point
  IniDocument out;
  out.set("s", "y", 0.25);
  EXPECT_NE(out.toString().find("y = 0.25"), std::string::npos);
  std::setlocale(LC_ALL, "C");
}

TEST(Config, EveryEstimatorSettingRoundTripsThroughItsSection) {
  // Every field away from its default, written, read back: each key is read
  // from the section it is written to (a key the reader skipped stays default).
  const models::Radar2D radar;
  EstimatorOptions o(Method::Batch);
  o.ekf.constant_process_noise = Eigen::Vector2d(1e-6, 2e-6);
  o.ekf.joseph_form = false;
  o.smoother.relinearize = false;
  o.smoother.relinearize_threshold = 0.25;
  o.smoother.constants_check_sigmas = 2.5;
  o.smoother.max_local_iterations = 7;
  o.smoother.wildfire_threshold = 1e-3;
  o.smoother.iterate_to_convergence = true;
  o.smoother.convergence_tolerance = 1e-7;
  o.smoother.max_iterations = 77;
  o.smoother.newton_polish_steps = 2;
  o.incremental.ordering = EliminationOrdering::TimeOrdered;
  o.fixed_lag.window = 17;
  o.paper_window.window = 19;
  o.batch.method = BatchSolverOptions::Method::GaussNewton;
  o.batch.max_iterations = 33;
  o.batch.relative_cost_tolerance = 1e-9;
  o.batch.step_tolerance = 1e-7;
  o.batch.gradient_tolerance = 1e-6;
  o.batch.initial_lambda = 1e-3;
  o.batch.max_lambda = 1e9;
  o.batch.newton_polish_steps = 3;
  IniDocument ini;
  writeModel(radar, ini);
  writeEstimatorOptions(o, ini);
  const EstimatorOptions r = estimatorOptions(IniDocument::parse(ini.toString(), "o.ini"), radar, Method::Batch);
  IniDocument again;
  writeEstimatorOptions(r, again);
  EXPECT_EQ(again.toString(), IniDocument::parse(ini.toString()).toString().substr(ini.toString().find("[ekf]")));
  EXPECT_EQ(r.smoother.max_local_iterations, 7);
  EXPECT_EQ(r.batch.method, BatchSolverOptions::Method::GaussNewton);
  EXPECT_EQ(r.batch.max_lambda, 1e9);
  EXPECT_EQ(r.paper_window.window, 19);
  EXPECT_EQ(r.incremental.ordering, EliminationOrdering::TimeOrdered);
  // Every section's key list is what the reader accepts, and no more.
  for (const auto& [section, keys] : estimatorIniKeys()) {
    EXPECT_FALSE(keys.empty()) << section;
    IniDocument bad = IniDocument::parse(ini.toString(), "bad.ini");
    bad.set(section, "not_a_key", "1");
    try {
      estimatorOptions(bad, radar);
      ADD_FAILURE() << section << ": an unknown key was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("not_a_key"), std::string::npos) << e.what();
    }
  }
}
