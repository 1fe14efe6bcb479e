#pragma once
// The model registry (docs/DESIGN.md §3, "Adding a model"): each model type
// registers itself once, next to its own code, with its name (the INI's
// [model] type, the checkpoint's model tag, Model::name()), its parameters,
// and how it reads and writes them. The INI reader and writer, checkpoints
// and the Python module consult the registry; no code outside a model's own
// files compares a model type's name as text.
//
//   // in my_model.cpp
//   static const gssm::ModelRegistration registration{{
//       "my_model", {}, "MyModel", "What it models, in one line.",
//       {{"model", "T", gssm::ParamKind::Real, false, "nominal step (s)"}, ...},
//       [](const gssm::ParamSource& in) { ...; return std::make_unique<MyModel>(p); },
//       [](const gssm::Model& m, gssm::ParamSink& out) { ... }}};
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gssm/model/model.h"
#include "gssm/model/params.h"

namespace gssm {

struct ModelType {
  std::string name;                  ///< "radar_2d": [model] type, checkpoint tag, Model::name()
  std::vector<std::string> aliases;  ///< older names still accepted ("radar2d")
  std::string class_name;            ///< "Radar2D": its class in Python (gssm.models.Radar2D)
  std::string summary;               ///< one line: what it models
  std::vector<ParamSpec> params;     ///< every parameter it reads and writes
  /// Builds the model; errors name where the bad value is (source.where).
  std::function<std::unique_ptr<Model>(const ParamSource&)> read;
  /// Writes every parameter of a model of this type (one `read` rebuilds it).
  std::function<void(const Model&, ParamSink&)> write;
  /// Whether `model` is of this type (a dynamic_cast in the model's own file).
  std::function<bool(const Model&)> owns;
  /// Optional: writes the value each parameter takes when a source leaves it
  /// out (the manual's INI reference shows them).
  std::function<void(ParamSink&)> defaults;

  const ParamSpec* param(const std::string& section, const std::string& key) const;
  /// The Sections parameter whose sub-sections are "<prefix>.<name>", if any.
  const ParamSpec* sectionsParam(const std::string& prefix) const;
  /// Its keyword parameters (Python's): every one but a sub-section's keys.
  std::vector<const ParamSpec*> keywordParams() const;
  /// The [section]s its parameters live in (not sub-sections).
  std::vector<std::string> sections() const;
  /// Keys declared in `section` (for a sub-section "channel.gps": those of "channel").
  std::vector<std::string> keysOf(const std::string& section) const;
};

/// Adds a model type; InvalidArgument if its name, an alias or its class
/// name is taken, or a declaration is incomplete. Thread-safe.
void registerModelType(ModelType type);
/// The type registered as `name` or one of its aliases; null if none.
const ModelType* findModelType(const std::string& name);
/// The registered type of `model`; null for a model not registered
/// (a FunctionModel, a user's model without a registration).
const ModelType* modelTypeOf(const Model& model);
/// Every registered type, in the order registered.
std::vector<const ModelType*> modelTypes();
/// "radar_2d, linear, ..." for messages.
std::string modelTypeNames();

/// Registers a type when constructed: one static object per model, in its
/// own source file.
struct ModelRegistration {
  explicit ModelRegistration(ModelType type) { registerModelType(std::move(type)); }
};

}  // namespace gssm
