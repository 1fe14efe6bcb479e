#pragma once
// A model's parameters as named, typed values (docs/DESIGN.md §3, "Adding a
// model"). A model type declares its parameters once (ParamSpec) and reads
// them from a ParamSource, writes them to a ParamSink. The INI reader, the
// Python keywords and the stubs are all sources and sinks of the same list,
// so a model's parameters are named in one place.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace gssm {

enum class ParamKind {
  Real,      ///< a number
  Flag,      ///< true/false
  Text,      ///< a word ("exact", "huber")
  Names,     ///< a list of words ("x v")
  Vector,    ///< numbers
  Matrix,    ///< rows of numbers (a vector of n is read as an n×n diagonal)
  Table,     ///< rows of numbers inline, or a data file with the named columns
  Sections,  ///< names of sub-sections "<prefix>.<name>", each with its own keys (a model's channels)
  Any        ///< numbers, or a word (a start position, or "truth")
};

/// One parameter: where it lives ([section] key) and what it holds. In
/// Python the keyword is `key` for [model] and `<section>_<key>` otherwise
/// (pythonKey); a Sections parameter takes a list of dicts there.
/// The Python keyword of [section] key: `key` for [model], `<section>_<key>` otherwise.
inline std::string pythonKeyOf(const std::string& section, const std::string& key) {
  return section == "model" ? key : section + "_" + key;
}

struct ParamSpec {
  std::string section;      ///< "model", "prior", or a sub-section prefix ("channel")
  std::string key;
  ParamKind kind = ParamKind::Real;
  bool required = false;    ///< no default: the source must give it
  std::string doc;          ///< one line, with the unit
  std::vector<std::string> columns;  ///< Table: its data file's columns, in order
  std::string subsection;   ///< Sections: the prefix of its sub-sections ("channel")
  /// A noise level learning may fit (docs/DESIGN.md §10): a Real is a
  /// standard deviation or a correlation time (> 0, searched in its log); a Matrix a covariance whose
  /// diagonal scales are fitted (each entry a variance, correlations kept).
  bool learnable = false;
  /// A learnable σ of the constants' prior (their spread across links,
  /// say): learnt by EM on the factor graph from the batch posterior of
  /// x_b (docs/DESIGN.md §10), not by the filter's likelihood.
  bool constants_prior = false;
  std::string pythonKey() const { return pythonKeyOf(section, key); }
};

/// Declarations, read as a list: {param::real("model", "T", "nominal step (s)"), ...}.
namespace param {
inline ParamSpec of(ParamKind kind, std::string section, std::string key, std::string doc) {
  ParamSpec p;
  p.section = std::move(section), p.key = std::move(key), p.kind = kind, p.doc = std::move(doc);
  return p;
}
inline ParamSpec real(std::string s, std::string k, std::string doc) { return of(ParamKind::Real, s, k, doc); }
inline ParamSpec flag(std::string s, std::string k, std::string doc) { return of(ParamKind::Flag, s, k, doc); }
inline ParamSpec text(std::string s, std::string k, std::string doc) { return of(ParamKind::Text, s, k, doc); }
inline ParamSpec names(std::string s, std::string k, std::string doc) { return of(ParamKind::Names, s, k, doc); }
inline ParamSpec vector(std::string s, std::string k, std::string doc) { return of(ParamKind::Vector, s, k, doc); }
inline ParamSpec matrix(std::string s, std::string k, std::string doc) { return of(ParamKind::Matrix, s, k, doc); }
inline ParamSpec any(std::string s, std::string k, std::string doc) { return of(ParamKind::Any, s, k, doc); }
inline ParamSpec table(std::string s, std::string k, std::vector<std::string> columns, std::string doc) {
  ParamSpec p = of(ParamKind::Table, s, k, doc);
  p.columns = std::move(columns);
  return p;
}
inline ParamSpec sections(std::string s, std::string k, std::string subsection, std::string doc) {
  ParamSpec p = of(ParamKind::Sections, s, k, doc);
  p.subsection = std::move(subsection);
  return p;
}
/// The same declaration, marked as a noise level that can be learnt.
inline ParamSpec learnable(ParamSpec p) {
  p.learnable = true;
  return p;
}
/// The same declaration, marked as a σ of the constants' prior that can be
/// learnt (by EM on the factor graph).
inline ParamSpec learnablePrior(ParamSpec p) {
  p.learnable = p.constants_prior = true;
  return p;
}
/// The same declaration, without a default: the source must give it.
inline ParamSpec required(ParamSpec p) {
  p.required = true;
  return p;
}
}  // namespace param

/// Where a model's parameters come from (an INI file, Python keywords).
/// Every getter throws InputError or InvalidArgument naming where the value
/// is (`where(section, key)`) and what was expected.
class ParamSource {
 public:
  virtual ~ParamSource() = default;
  virtual bool has(const std::string& section, const std::string& key) const = 0;
  virtual double real(const std::string& section, const std::string& key) const = 0;
  virtual bool flag(const std::string& section, const std::string& key) const = 0;
  virtual std::string text(const std::string& section, const std::string& key) const = 0;
  virtual std::vector<std::string> names(const std::string& section, const std::string& key) const = 0;
  /// `size` < 0: any length.
  virtual Eigen::VectorXd vector(const std::string& section, const std::string& key, Eigen::Index size = -1) const = 0;
  /// `rows`, `cols` < 0: any; a vector of n entries with rows = cols = n is a diagonal.
  virtual Eigen::MatrixXd matrix(const std::string& section, const std::string& key, Eigen::Index rows = -1,
                                 Eigen::Index cols = -1) const = 0;
  /// Rows of `columns.size()` numbers: given inline, or (INI) a CSV file with
  /// those columns, read from the dataset folder.
  virtual Eigen::MatrixXd table(const std::string& section, const std::string& key,
                                const std::vector<std::string>& columns) const = 0;
  /// The named columns of a data file (`file` relative to the dataset
  /// folder); InvalidArgument where the source has no files (Python).
  virtual Eigen::MatrixXd dataFile(const std::string& file, const std::vector<std::string>& columns) const = 0;
  /// Whether such a file is there (an optional file of a data set).
  virtual bool hasDataFile(const std::string& /*file*/) const { return true; }
  /// "scenario.ini: [model] T" or "RangeBeacon2D(range_sd=...)": for messages.
  virtual std::string where(const std::string& section, const std::string& key) const = 0;

  // With a fallback when absent.
  double real(const std::string& s, const std::string& k, double fallback) const {
    return has(s, k) ? real(s, k) : fallback;
  }
  bool flag(const std::string& s, const std::string& k, bool fallback) const { return has(s, k) ? flag(s, k) : fallback; }
  std::string text(const std::string& s, const std::string& k, const std::string& fallback) const {
    return has(s, k) ? text(s, k) : fallback;
  }
};

/// Where a model's parameters go (an INI file, a Python dict).
class ParamSink {
 public:
  virtual ~ParamSink() = default;
  virtual void real(const std::string& section, const std::string& key, double value) = 0;
  virtual void flag(const std::string& section, const std::string& key, bool value) = 0;
  virtual void text(const std::string& section, const std::string& key, const std::string& value) = 0;
  virtual void names(const std::string& section, const std::string& key, const std::vector<std::string>& value) = 0;
  virtual void vector(const std::string& section, const std::string& key, const Eigen::VectorXd& value) = 0;
  virtual void matrix(const std::string& section, const std::string& key, const Eigen::MatrixXd& value) = 0;
};

}  // namespace gssm
