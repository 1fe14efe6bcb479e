#include "gssm/model/param_values.h"

#include <sstream>

#include "gssm/core/error.h"
#include "gssm/model/registry.h"

namespace gssm {

ParamValues ParamValues::of(const Model& model) {
  const ModelType* type = modelTypeOf(model);
  if (!type)
    throw InvalidArgument("model '" + model.name() +
                          "' has no registered type: its parameters cannot be read (see ModelRegistration)");
  ParamValues v;
  type->write(model, v);
  return v;
}

std::unique_ptr<Model> ParamValues::build(const std::string& type_name) const {
  const ModelType* type = findModelType(type_name);
  if (!type) throw InvalidArgument("no model type '" + type_name + "' (known: " + modelTypeNames() + ")");
  return type->read(*this);
}

bool ParamValues::has(const std::string& section, const std::string& key) const {
  return values_.count({section, key}) > 0;
}

const ParamValues::Value* ParamValues::find(const std::string& section, const std::string& key) const {
  auto it = values_.find({section, key});
  return it == values_.end() ? nullptr : &it->second;
}

const ParamValues::Value& ParamValues::at(const std::string& section, const std::string& key) const {
  const Value* v = find(section, key);
  if (!v) throw InvalidArgument(where(section, key) + ": not given");
  return *v;
}

template <class T>
const T& ParamValues::as(const std::string& section, const std::string& key, const char* what) const {
  const T* v = std::get_if<T>(&at(section, key));
  if (!v) throw InvalidArgument(where(section, key) + ": expected " + what);
  return *v;
}

double ParamValues::real(const std::string& section, const std::string& key) const {
  return as<double>(section, key, "a number");
}
bool ParamValues::flag(const std::string& section, const std::string& key) const {
  return as<bool>(section, key, "true or false");
}
std::string ParamValues::text(const std::string& section, const std::string& key) const {
  // Numbers read as text as an INI file would give them ("1.5 2"): an Any
  // parameter (a start that is a position or "truth") is tested as a word.
  const Value& v = at(section, key);
  if (const auto* s = std::get_if<std::string>(&v)) return *s;
  std::ostringstream os;
  os.precision(17);
  if (const auto* d = std::get_if<double>(&v)) os << *d;
  if (const auto* m = std::get_if<Eigen::MatrixXd>(&v))
    for (Eigen::Index i = 0; i < m->size(); ++i) os << (i ? " " : "") << m->data()[i];
  if (os.str().empty()) throw InvalidArgument(where(section, key) + ": expected a word");
  return os.str();
}
std::vector<std::string> ParamValues::names(const std::string& section, const std::string& key) const {
  return as<std::vector<std::string>>(section, key, "a list of names");
}

Eigen::VectorXd ParamValues::vector(const std::string& section, const std::string& key, Eigen::Index size) const {
  const Eigen::MatrixXd& m = as<Eigen::MatrixXd>(section, key, "numbers");
  if (m.cols() != 1 && m.rows() != 1) throw InvalidArgument(where(section, key) + ": expected a vector");
  Eigen::VectorXd v = Eigen::Map<const Eigen::VectorXd>(m.data(), m.size());
  if (size >= 0 && v.size() != size)
    throw InvalidArgument(where(section, key) + ": expected " + std::to_string(size) + " numbers, got " +
                          std::to_string(v.size()));
  return v;
}

Eigen::MatrixXd ParamValues::matrix(const std::string& section, const std::string& key, Eigen::Index rows,
                                    Eigen::Index cols) const {
  Eigen::MatrixXd m = as<Eigen::MatrixXd>(section, key, "a matrix");
  if (rows >= 0 && rows == cols && m.cols() == 1 && m.rows() == rows && rows > 1) m = m.col(0).asDiagonal();
  if ((rows >= 0 && m.rows() != rows) || (cols >= 0 && m.cols() != cols))
    throw InvalidArgument(where(section, key) + ": expected " + std::to_string(rows) + "×" + std::to_string(cols) +
                          ", got " + std::to_string(m.rows()) + "×" + std::to_string(m.cols()));
  return m;
}

Eigen::MatrixXd ParamValues::table(const std::string& section, const std::string& key,
                                   const std::vector<std::string>& columns) const {
  return matrix(section, key, -1, static_cast<Eigen::Index>(columns.size()));
}

Eigen::MatrixXd ParamValues::dataFile(const std::string& file, const std::vector<std::string>&) const {
  throw InvalidArgument("model parameters held in memory: no data file to read ('" + file + "')");
}

std::string ParamValues::where(const std::string& section, const std::string& key) const {
  return "[" + section + "] " + key;
}

void ParamValues::real(const std::string& s, const std::string& k, double v) { values_[{s, k}] = v; }
void ParamValues::flag(const std::string& s, const std::string& k, bool v) { values_[{s, k}] = v; }
void ParamValues::text(const std::string& s, const std::string& k, const std::string& v) { values_[{s, k}] = v; }
void ParamValues::names(const std::string& s, const std::string& k, const std::vector<std::string>& v) {
  values_[{s, k}] = v;
}
void ParamValues::vector(const std::string& s, const std::string& k, const Eigen::VectorXd& v) {
  values_[{s, k}] = Eigen::MatrixXd(v);
}
void ParamValues::matrix(const std::string& s, const std::string& k, const Eigen::MatrixXd& v) { values_[{s, k}] = v; }

std::vector<std::pair<std::string, std::string>> ParamValues::keys() const {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& kv : values_) out.push_back(kv.first);
  return out;
}

}  // namespace gssm
