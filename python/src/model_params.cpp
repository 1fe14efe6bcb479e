// gssm.models' registered model types (docs/DESIGN.md §3, "Adding a
// model"): each type's parameters become the keywords of its Python class,
// read through the same ParamSource as the INI reader, and written back as
// a dict (Model.params). Keyword names: the INI key for [model], and
// <section>_<key> otherwise; a Sections parameter (a linear model's
// channels) is a list of dicts with a "name".
#include <sstream>

#include "bindings.h"
#include "gssm/core/error.h"
#include "gssm/model/registry.h"

namespace gssm::python {

namespace {

using namespace pybind11::literals;
using Eigen::MatrixXd;
using Eigen::VectorXd;

class DictParamSource final : public ParamSource {
 public:
  DictParamSource(const ModelType& type, py::dict kwargs) : type_(type), kwargs_(std::move(kwargs)) {}
  bool has(const std::string& s, const std::string& k) const override { return !lookup(s, k).is_none(); }
  double real(const std::string& s, const std::string& k) const override {
    return as<double>(s, k, "a number");
  }
  bool flag(const std::string& s, const std::string& k) const override {
    const py::object v = need(s, k);
    if (!py::isinstance<py::bool_>(v) && !py::isinstance<py::int_>(v)) fail(s, k, "expected True or False");
    return v.cast<bool>();
  }
  std::string text(const std::string& s, const std::string& k) const override { return as<std::string>(s, k, "a str"); }
  std::vector<std::string> names(const std::string& s, const std::string& k) const override;
  VectorXd vector(const std::string& s, const std::string& k, Eigen::Index n) const override;
  MatrixXd matrix(const std::string& s, const std::string& k, Eigen::Index rows, Eigen::Index cols) const override;
  MatrixXd table(const std::string& s, const std::string& k, const std::vector<std::string>& columns) const override {
    return matrix(s, k, -1, static_cast<Eigen::Index>(columns.size()));
  }
  MatrixXd dataFile(const std::string& file, const std::vector<std::string>&) const override {
    throw InvalidArgument(type_.class_name + ": reads the data file '" + file +
                          "' only from an INI file; give the numbers instead");
  }
  std::string where(const std::string& s, const std::string& k) const override {
    return "gssm.models." + type_.class_name + "(" + pythonKey(s, k) + "=...)";
  }

 private:
  std::string pythonKey(const std::string& s, const std::string& k) const {
    const auto dot = s.find('.');
    if (dot != std::string::npos) {
      const ParamSpec* p = type_.sectionsParam(s.substr(0, dot));
      return (p ? p->pythonKey() : s) + "['" + s.substr(dot + 1) + "']['" + k + "']";
    }
    return pythonKeyOf(s, k);
  }
  py::object lookup(const std::string& s, const std::string& k) const;
  py::object need(const std::string& s, const std::string& k) const {
    py::object v = lookup(s, k);
    if (v.is_none()) fail(s, k, "missing: this parameter has no default");
    return v;
  }
  template <class T>
  T as(const std::string& s, const std::string& k, const char* what) const {
    try {
      return need(s, k).cast<T>();
    } catch (const py::cast_error&) {
      fail(s, k, std::string("expected ") + what);
    }
  }
  MatrixXd array2d(const std::string& s, const std::string& k) const;
  [[noreturn]] void fail(const std::string& s, const std::string& k, const std::string& why) const {
    throw InvalidArgument(where(s, k) + ": " + why);
  }
  const ModelType& type_;
  py::dict kwargs_;
};

py::object DictParamSource::lookup(const std::string& s, const std::string& k) const {
  const auto dot = s.find('.');
  if (dot == std::string::npos) {
    const std::string key = pythonKeyOf(s, k);
    return kwargs_.contains(key) ? py::reinterpret_borrow<py::object>(kwargs_[key.c_str()]) : py::none();
  }
  const ParamSpec* p = type_.sectionsParam(s.substr(0, dot));
  if (!p || !kwargs_.contains(p->pythonKey())) return py::none();
  for (const py::handle item : kwargs_[p->pythonKey().c_str()]) {
    const py::dict d = py::reinterpret_borrow<py::dict>(item);
    if (d.contains("name") && d["name"].cast<std::string>() == s.substr(dot + 1))
      return d.contains(k) ? py::reinterpret_borrow<py::object>(d[k.c_str()]) : py::none();
  }
  return py::none();
}

std::vector<std::string> DictParamSource::names(const std::string& s, const std::string& k) const {
  const py::object v = need(s, k);
  std::vector<std::string> out;
  if (py::isinstance<py::str>(v)) {
    std::istringstream words(v.cast<std::string>());
    for (std::string w; words >> w;) out.push_back(w);
    return out;
  }
  for (const py::handle item : v) {
    if (py::isinstance<py::dict>(item)) out.push_back(py::reinterpret_borrow<py::dict>(item)["name"].cast<std::string>());
    else out.push_back(py::str(item).cast<std::string>());
  }
  return out;
}

MatrixXd DictParamSource::array2d(const std::string& s, const std::string& k) const {
  const py::object np = py::module_::import("numpy");
  py::object a;
  try {
    a = np.attr("asarray")(need(s, k), "dtype"_a = "float64");
  } catch (const py::error_already_set&) {
    fail(s, k, "expected numbers");
  }
  const int ndim = a.attr("ndim").cast<int>();
  if (ndim > 2) fail(s, k, "expected at most 2 dimensions");
  return np.attr("atleast_2d")(a).cast<MatrixXd>();
}

VectorXd DictParamSource::vector(const std::string& s, const std::string& k, Eigen::Index n) const {
  const MatrixXd m = array2d(s, k);
  if (m.rows() != 1 && m.cols() != 1) fail(s, k, "expected a vector");
  const VectorXd v = m.rows() == 1 ? VectorXd(m.row(0).transpose()) : VectorXd(m.col(0));
  if (n >= 0 && v.size() != n) fail(s, k, "expected " + std::to_string(n) + " values, got " + std::to_string(v.size()));
  return v;
}

MatrixXd DictParamSource::matrix(const std::string& s, const std::string& k, Eigen::Index rows,
                                 Eigen::Index cols) const {
  MatrixXd m = array2d(s, k);
  // A vector of n entries where an n×n matrix is expected is its diagonal (as in the INI).
  if (rows >= 0 && rows == cols && m.rows() == 1 && m.cols() == rows && rows > 1) m = MatrixXd(m.row(0).asDiagonal());
  if ((rows >= 0 && m.rows() != rows) || (cols >= 0 && m.cols() != cols))
    fail(s, k, "shape (" + std::to_string(m.rows()) + ", " + std::to_string(m.cols()) + "), expected (" +
                   (rows >= 0 ? std::to_string(rows) : "any") + ", " + (cols >= 0 ? std::to_string(cols) : "any") + ")");
  return m;
}

// Model.params: the written parameters as a dict of Python keywords.
class DictParamSink final : public ParamSink {
 public:
  explicit DictParamSink(const ModelType& type) : type_(type) {}
  void real(const std::string& s, const std::string& k, double v) override { put(s, k, py::float_(v)); }
  void flag(const std::string& s, const std::string& k, bool v) override { put(s, k, py::bool_(v)); }
  void text(const std::string& s, const std::string& k, const std::string& v) override { put(s, k, py::str(v)); }
  void names(const std::string& s, const std::string& k, const std::vector<std::string>& v) override {
    const ParamSpec* p = type_.param(s, k);
    if (p && p->kind == ParamKind::Sections) return;  // the list of dicts its sub-sections filled
    put(s, k, py::cast(v));
  }
  void vector(const std::string& s, const std::string& k, const VectorXd& v) override { put(s, k, py::cast(v)); }
  void matrix(const std::string& s, const std::string& k, const MatrixXd& v) override { put(s, k, py::cast(v)); }
  py::dict result() const { return out_; }

 private:
  void put(const std::string& s, const std::string& k, py::object v);
  const ModelType& type_;
  py::dict out_;
};

void DictParamSink::put(const std::string& s, const std::string& k, py::object v) {
  const auto dot = s.find('.');
  if (dot == std::string::npos) {
    out_[pythonKeyOf(s, k).c_str()] = v;
    return;
  }
  const ParamSpec* p = type_.sectionsParam(s.substr(0, dot));
  const std::string key = p ? p->pythonKey() : s.substr(0, dot);
  if (!out_.contains(key)) out_[key.c_str()] = py::list();
  py::list list = out_[key.c_str()];
  const std::string name = s.substr(dot + 1);
  for (const py::handle item : list) {
    py::dict d = py::reinterpret_borrow<py::dict>(item);
    if (d["name"].cast<std::string>() == name) return void(d[k.c_str()] = v);
  }
  py::dict d;
  d["name"] = name;
  d[k.c_str()] = v;
  list.append(d);
}

const char* kindName(ParamKind k) {
  switch (k) {
    case ParamKind::Real: return "real";
    case ParamKind::Flag: return "flag";
    case ParamKind::Text: return "text";
    case ParamKind::Names: return "names";
    case ParamKind::Vector: return "vector";
    case ParamKind::Matrix: return "matrix";
    case ParamKind::Table: return "table";
    case ParamKind::Sections: return "sections";
    case ParamKind::Any: return "any";
  }
  return "?";
}

py::dict typeInfo(const ModelType& t) {
  py::list params;
  for (const ParamSpec* p : t.keywordParams())  // a sub-section's keys are in its list of dicts
    params.append(py::dict("name"_a = p->pythonKey(), "section"_a = p->section, "key"_a = p->key,
                           "kind"_a = kindName(p->kind), "required"_a = p->required, "doc"_a = p->doc));
  return py::dict("name"_a = t.name, "aliases"_a = t.aliases, "class_name"_a = t.class_name,
                  "summary"_a = t.summary, "params"_a = params);
}

const ModelType& typeNamed(const std::string& name) {
  const ModelType* t = findModelType(name);
  if (!t) throw InvalidArgument("unknown model type '" + name + "' (known: " + modelTypeNames() + ")");
  return *t;
}

std::shared_ptr<Model> makeRegistered(const std::string& name, const py::dict& kwargs) {
  const ModelType& t = typeNamed(name);
  const std::vector<const ParamSpec*> keywords = t.keywordParams();
  for (const auto& item : kwargs) {
    const std::string key = py::str(item.first).cast<std::string>();
    if (std::any_of(keywords.begin(), keywords.end(), [&](const ParamSpec* p) { return p->pythonKey() == key; }))
      continue;
    std::string list;
    for (const ParamSpec* p : keywords) list += (list.empty() ? "" : ", ") + p->pythonKey();
    throw InvalidArgument("gssm.models." + t.class_name + ": unknown parameter '" + key + "' (known: " + list + ")");
  }
  return std::shared_ptr<Model>(t.read(DictParamSource(t, kwargs)));
}

}  // namespace

py::dict modelParams(const Model& m) {
  const ModelType* t = modelTypeOf(m);
  if (!t) throw InvalidArgument("model '" + m.name() + "' is not a registered type: it has no parameters to list");
  DictParamSink out(*t);
  t->write(m, out);
  return out.result();
}

void bindModelRegistry(py::module_& models) {
  models.def(
      "_types",
      [] {
        py::list out;
        for (const ModelType* t : modelTypes()) out.append(typeInfo(*t));
        return out;
      },
      "Every registered model type: name, aliases, class_name, summary, params.");
  models.def("_make", &makeRegistered, py::arg("type"), py::arg("params"),
             "The registered model `type` from its parameters (Python keywords).");
  models.def(
      "_type_of", [](const Model& m) -> py::object {
        const ModelType* t = modelTypeOf(m);
        return t ? py::object(py::str(t->name)) : py::object(py::none());
      },
      py::arg("model"));
  
}

}  // namespace gssm::python
