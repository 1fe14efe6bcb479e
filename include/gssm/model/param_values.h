#pragma once
// A model's parameters held in memory: a ParamSink that is also a
// ParamSource. Writing a model into one and reading it back rebuilds the
// same model; changing a value in between rebuilds it with that value (what
// noise learning does for every likelihood it evaluates).
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "gssm/model/model.h"
#include "gssm/model/params.h"

namespace gssm {

class ParamValues final : public ParamSource, public ParamSink {
 public:
  using Value = std::variant<double, bool, std::string, std::vector<std::string>, Eigen::MatrixXd>;

  /// Every parameter of `model` (its registered type's write); InvalidArgument
  /// for a model whose type is not registered.
  static ParamValues of(const Model& model);
  /// Rebuilds a model of `type_name` from these values.
  std::unique_ptr<Model> build(const std::string& type_name) const;

  // ParamSource
  bool has(const std::string& section, const std::string& key) const override;
  double real(const std::string& section, const std::string& key) const override;
  bool flag(const std::string& section, const std::string& key) const override;
  std::string text(const std::string& section, const std::string& key) const override;
  std::vector<std::string> names(const std::string& section, const std::string& key) const override;
  Eigen::VectorXd vector(const std::string& section, const std::string& key, Eigen::Index size = -1) const override;
  Eigen::MatrixXd matrix(const std::string& section, const std::string& key, Eigen::Index rows = -1,
                         Eigen::Index cols = -1) const override;
  Eigen::MatrixXd table(const std::string& section, const std::string& key,
                        const std::vector<std::string>& columns) const override;
  Eigen::MatrixXd dataFile(const std::string& file, const std::vector<std::string>& columns) const override;
  std::string where(const std::string& section, const std::string& key) const override;
  using ParamSource::flag;
  using ParamSource::real;
  using ParamSource::text;

  // ParamSink
  void real(const std::string& section, const std::string& key, double value) override;
  void flag(const std::string& section, const std::string& key, bool value) override;
  void text(const std::string& section, const std::string& key, const std::string& value) override;
  void names(const std::string& section, const std::string& key, const std::vector<std::string>& value) override;
  void vector(const std::string& section, const std::string& key, const Eigen::VectorXd& value) override;
  void matrix(const std::string& section, const std::string& key, const Eigen::MatrixXd& value) override;

  /// Every (section, key) held, in order.
  std::vector<std::pair<std::string, std::string>> keys() const;
  const Value* find(const std::string& section, const std::string& key) const;

 private:
  const Value& at(const std::string& section, const std::string& key) const;
  template <class T>
  const T& as(const std::string& section, const std::string& key, const char* what) const;
  std::map<std::pair<std::string, std::string>, Value> values_;
};

}  // namespace gssm
