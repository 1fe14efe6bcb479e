// Text as editors and spreadsheets write it: a UTF-8 byte-order mark at the
// start of a CSV or INI file is skipped, and a character a reader cannot see
// is named by its code point in every input error.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/io/csv.h"
#include "gssm/io/ini.h"
#include "gssm/io/process.h"

using namespace gssm;
namespace fs = std::filesystem;

namespace {
const std::string kBom = "\xEF\xBB\xBF";

std::string fileText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The dataset `name` copied to a temporary folder, a BOM before every CSV and INI file's text.
fs::path copyWithByteOrderMarks(const std::string& name) {
  const fs::path from = fs::path(GSSM_SOURCE_DIR) / "datasets" / name;
  const fs::path to = fs::path(::testing::TempDir()) / ("bom-" + name);
  fs::remove_all(to);
  fs::create_directories(to);
  for (const auto& entry : fs::directory_iterator(from)) {
    const std::string ext = entry.path().extension().string();
    std::ofstream out(to / entry.path().filename(), std::ios::binary);
    out << (ext == ".csv" || ext == ".ini" ? kBom : "") << fileText(entry.path());
  }
  return to;
}

// Every estimates-<method>.csv a run of `dir` writes, by file name.
std::map<std::string, std::string> estimatesOf(const fs::path& dir, const std::string& out,
                                               const std::vector<Method>& methods) {
  io::ProcessOptions o;
  o.data_dir = dir.string();
  o.out_dir = (fs::path(::testing::TempDir()) / out).string();
  o.methods = methods;
  io::processDataset(o);
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::directory_iterator(o.out_dir))
    if (entry.path().filename().string().rfind("estimates-", 0) == 0) files[entry.path().filename().string()] = fileText(entry.path());
  return files;
}

void expectSameEstimatesWithByteOrderMarks(const std::string& name, const std::vector<Method>& methods) {
  const auto plain = estimatesOf(fs::path(GSSM_SOURCE_DIR) / "datasets" / name, "plain-" + name, methods);
  const auto marked = estimatesOf(copyWithByteOrderMarks(name), "marked-" + name, methods);
  ASSERT_EQ(plain.size(), methods.size());
  ASSERT_EQ(marked.size(), plain.size());
  for (const auto& [file, text] : plain) {
    EXPECT_FALSE(text.empty()) << file;
    EXPECT_TRUE(marked.at(file) == text) << name << "/" << file << " differs with byte-order marks";
  }
}
}  // namespace

TEST(TextEncoding, InvisibleCharactersAreShownAsCodePoints) {
  EXPECT_EQ(showInvisible(kBom + "t,range"), "<U+FEFF>t,range");
  EXPECT_EQ(showInvisible("a\xE2\x80\x8B" "b"), "a<U+200B>b");          // zero-width space
  EXPECT_EQ(showInvisible("1\xC2\xA0" "5"), "1<U+00A0>5");              // non-breaking space
  EXPECT_EQ(showInvisible(std::string("x\0y", 3)), "x<U+0000>y");
  EXPECT_EQ(showInvisible("caf\xE9"), "caf<0xE9>");                     // Latin-1, not UTF-8
  EXPECT_EQ(showInvisible("\xC0\xAF"), "<0xC0><0xAF>");                 // overlong '/'
  EXPECT_EQ(showInvisible("σ ≥ 0\tline\n"), "σ ≥ 0\tline\n");           // visible text unchanged
}

TEST(TextEncoding, AnInvisibleCharacterInAFileIsNamedInTheError) {
  try {
    io::parseCsv("t,\xE2\x80\x8Brange\n0,x\n", "m.csv");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("m.csv:2: column '<U+200B>range'"), std::string::npos) << e.what();
  }
  try {
    io::IniDocument::parse("[model]\nrange_sd\xC2\xA0" "0.5\n", "s.ini");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.ini:2: expected 'key = value', got 'range_sd<U+00A0>0.5'"), std::string::npos)
        << e.what();
  }
}

TEST(TextEncoding, AByteOrderMarkIsSkippedByTheCsvAndIniReaders) {
  const io::CsvTable t = io::parseCsv(kBom + "t,range\n0.5,2\n", "m.csv");
  ASSERT_EQ(t.header.size(), 2u);
  EXPECT_EQ(t.header[0], "t");
  EXPECT_EQ(t.column("t"), 0);
  const io::IniDocument ini = io::IniDocument::parse(kBom + "[model]\ntype = radar_2d\n", "s.ini");
  EXPECT_EQ(ini.getString("model", "type"), "radar_2d");
  // Only at the start: elsewhere it is a character of the text, named in errors.
  EXPECT_THROW(io::parseCsv("t,range\n" + kBom + "0.5,2\n", "m.csv"), InputError);
}

TEST(TextEncoding, DatasetsWithByteOrderMarksGiveTheSameEstimates) {
  expectSameEstimatesWithByteOrderMarks("radar-paper", {Method::Ekf, Method::FixedLag, Method::PaperWindow});
  expectSameEstimatesWithByteOrderMarks("plaza2", {Method::Ekf, Method::Batch});
}
