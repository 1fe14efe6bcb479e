// Models from and to INI text through the model registry (docs/DESIGN.md §3,
// "Adding a model"): an IniDocument seen as a ParamSource and a ParamSink.
#include <cmath>
#include <filesystem>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/io/config.h"
#include "gssm/io/csv.h"
#include "gssm/io/rtklib_pos.h"
#include "gssm/model/registry.h"

namespace gssm::io {

// A file named in the INI: in the dataset folder when one is given, else
// beside the INI.
std::string dataFile(const IniDocument& ini, const std::string& data_dir, const std::string& file) {
  const std::filesystem::path p(file);
  if (p.is_absolute()) return file;
  const std::filesystem::path base = data_dir.empty() ? std::filesystem::path(ini.source()).parent_path()
                                                      : std::filesystem::path(data_dir);
  return (base / p).string();
}

namespace {

std::string joined(const std::vector<std::string>& words, const char* sep) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : sep) + w;
  return out;
}

class IniParamSource final : public ParamSource {
 public:
  IniParamSource(const IniDocument& ini, std::string data_dir) : ini_(ini), data_dir_(std::move(data_dir)) {}
  bool has(const std::string& s, const std::string& k) const override { return ini_.has(s, k); }
  double real(const std::string& s, const std::string& k) const override { return ini_.getDouble(s, k); }
  bool flag(const std::string& s, const std::string& k) const override {
    if (!ini_.has(s, k)) ini_.getString(s, k);  // names the missing key
    return ini_.getBool(s, k, false);
  }
  std::string text(const std::string& s, const std::string& k) const override { return ini_.getString(s, k); }
  std::vector<std::string> names(const std::string& s, const std::string& k) const override {
    std::istringstream words(ini_.getString(s, k));
    std::vector<std::string> out;
    for (std::string w; words >> w;) out.push_back(w);
    return out;
  }
  Eigen::VectorXd vector(const std::string& s, const std::string& k, Eigen::Index n) const override {
    return ini_.getVector(s, k, n);
  }
  Eigen::MatrixXd matrix(const std::string& s, const std::string& k, Eigen::Index rows,
                         Eigen::Index cols) const override {
    return ini_.getMatrix(s, k, rows, cols);
  }
  // Inline rows of numbers, or the name of a CSV file (anything else).
  Eigen::MatrixXd table(const std::string& s, const std::string& k,
                        const std::vector<std::string>& columns) const override {
    const std::string value = ini_.getString(s, k);
    if (value.find_first_not_of("0123456789.-+eE \t;,[]") == std::string::npos) {
      const Eigen::MatrixXd rows = ini_.getMatrix(s, k);
      if (rows.cols() != static_cast<Eigen::Index>(columns.size()))
        throw InputError(where(s, k) + ": expected rows of '" + joined(columns, " ") + "' or a CSV file");
      return rows;
    }
    return dataFile(value, columns);
  }
  Eigen::MatrixXd dataFile(const std::string& file, const std::vector<std::string>& columns) const override;
  bool hasDataFile(const std::string& file) const override {
    return std::filesystem::exists(io::dataFile(ini_, data_dir_, file));
  }
  std::string where(const std::string& s, const std::string& k) const override { return ini_.where(s, k); }

 private:
  const IniDocument& ini_;
  std::string data_dir_;
};

Eigen::MatrixXd IniParamSource::dataFile(const std::string& file, const std::vector<std::string>& columns) const {
  const std::string path = io::dataFile(ini_, data_dir_, file);
  if (std::filesystem::path(path).extension() == ".pos") return solutionColumns(readRtklibPos(path), columns);
  const CsvTable t = readCsv(path);
  std::vector<std::size_t> at;
  for (const auto& c : columns) {
    const int i = t.column(c);
    if (i < 0) throw InputError(t.source + ":1: expected columns " + joined(columns, ","));
    at.push_back(static_cast<std::size_t>(i));
  }
  Eigen::MatrixXd out(static_cast<Eigen::Index>(t.rows.size()), static_cast<Eigen::Index>(columns.size()));
  for (std::size_t r = 0; r < t.rows.size(); ++r)
    for (std::size_t c = 0; c < at.size(); ++c)
      out(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = t.rows[r][at[c]];
  return out;
}

class IniParamSink final : public ParamSink {
 public:
  explicit IniParamSink(IniDocument& ini) : ini_(ini) {}
  void real(const std::string& s, const std::string& k, double v) override { ini_.set(s, k, v); }
  void flag(const std::string& s, const std::string& k, bool v) override { ini_.set(s, k, v ? "true" : "false"); }
  void text(const std::string& s, const std::string& k, const std::string& v) override { ini_.set(s, k, v); }
  void names(const std::string& s, const std::string& k, const std::vector<std::string>& v) override {
    ini_.set(s, k, joined(v, " "));
  }
  void vector(const std::string& s, const std::string& k, const Eigen::VectorXd& v) override {
    ini_.set(s, k, Eigen::MatrixXd(v.transpose()));
  }
  void matrix(const std::string& s, const std::string& k, const Eigen::MatrixXd& v) override { ini_.set(s, k, v); }

 private:
  IniDocument& ini_;
};

// Every section the type reads holds only its declared keys (catches typos).
void requireDeclaredKeys(const IniDocument& ini, const ModelType& type, const ParamSource& in) {
  for (const std::string& section : type.sections()) {
    std::vector<std::string> keys = type.keysOf(section);
    if (section == "model") keys.push_back("type");
    ini.requireOnlyKeys(section, keys);
  }
  for (const ParamSpec& p : type.params) {
    if (p.kind != ParamKind::Sections || !in.has(p.section, p.key)) continue;
    for (const std::string& name : in.names(p.section, p.key)) {
      const std::string section = p.subsection + "." + name;
      if (!ini.hasSection(section))
        throw InputError(in.where(p.section, p.key) + " names '" + name + "' but there is no [" + section + "]");
      ini.requireOnlyKeys(section, type.keysOf(section));
    }
  }
}
}  // namespace

std::unique_ptr<Model> makeModel(const IniDocument& ini, const std::string& data_dir) {
  const std::string name = ini.getString("model", "type");
  const ModelType* type = findModelType(name);
  if (!type)
    throw InputError(ini.where("model", "type") + " = '" + name + "': unknown model (known: " + modelTypeNames() + ")");
  const IniParamSource in(ini, data_dir);
  requireDeclaredKeys(ini, *type, in);
  try {
    return type->read(in);
  } catch (const InputError&) {
    throw;
  } catch (const Error& e) {  // model constructors validate covariances: say which file
    throw InputError(ini.source() + ": " + e.what());
  }
}

void writeModelDefaults(const ModelType& type, IniDocument& ini) {
  if (!type.defaults) return;
  IniParamSink out(ini);
  type.defaults(out);
}

void writeModel(const Model& model, IniDocument& ini) {
  const ModelType* type = modelTypeOf(model);
  if (!type) throw InvalidArgument("writeModel: model '" + model.name() + "' has no INI form (it is not registered)");
  ini.set("model", "type", type->name);
  IniParamSink out(ini);
  type->write(model, out);
}

}  // namespace gssm::io
