#include "gssm/model/registry.h"

#include <algorithm>
#include <deque>
#include <mutex>

#include "gssm/core/error.h"
#include "gssm/model/colored_noise.h"

namespace gssm {

namespace {
// One registry per process, built on first use (registrations run during
// static initialization, in any order).
struct Registry {
  std::mutex mutex;
  std::deque<ModelType> types;  // a deque: pointers stay valid as types are added
};

Registry& registry() {
  static Registry r;
  return r;
}

bool named(const ModelType& t, const std::string& name) {
  return t.name == name || std::find(t.aliases.begin(), t.aliases.end(), name) != t.aliases.end();
}

void requireComplete(const ModelType& t) {
  if (t.name.empty() || t.class_name.empty())
    throw InvalidArgument("registerModelType: a model type needs a name and a class name");
  if (!t.read || !t.write || !t.owns)
    throw InvalidArgument("registerModelType '" + t.name + "': read, write and owns must all be given");
  for (std::size_t i = 0; i < t.params.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (t.params[i].pythonKey() == t.params[j].pythonKey())
        throw InvalidArgument("registerModelType '" + t.name + "': parameter '" + t.params[i].pythonKey() +
                              "' declared twice");
}
// Every type takes coloured measurement noise on any of its channels
// (docs/DESIGN.md §9): the [colored_noise] keys, the wrapper applied after
// its own read, its own write and owns seeing through the wrapper.
ModelType takingColoredNoise(ModelType t) {
  if (t.param("colored_noise", "channels")) return t;
  for (auto& p : coloredNoiseParams()) t.params.push_back(std::move(p));
  t.read = [read = std::move(t.read)](const ParamSource& in) { return withColoredNoise(read(in), readColoredNoise(in)); };
  t.write = [write = std::move(t.write)](const Model& m, ParamSink& out) {
    write(withoutColoredNoise(m), out);
    if (const ColoredNoise* c = coloredNoiseOf(m)) writeColoredNoise(*c, out);
  };
  t.owns = [owns = std::move(t.owns)](const Model& m) { return owns(withoutColoredNoise(m)); };
  t.defaults = [defaults = std::move(t.defaults)](ParamSink& out) {
    if (defaults) defaults(out);
    const ColoredNoise none;  // τ and σ as a file that names channels but not them gets
    out.real("colored_noise", "tau", none.tau);
    out.real("colored_noise", "sd", none.sd);
  };
  return t;
}
}  // namespace

const ParamSpec* ModelType::param(const std::string& section, const std::string& key) const {
  for (const auto& p : params)
    if (p.section == section && p.key == key) return &p;
  return nullptr;
}

const ParamSpec* ModelType::sectionsParam(const std::string& prefix) const {
  for (const auto& p : params)
    if (p.kind == ParamKind::Sections && p.subsection == prefix) return &p;
  return nullptr;
}

std::vector<const ParamSpec*> ModelType::keywordParams() const {
  std::vector<const ParamSpec*> out;
  for (const auto& p : params)
    if (!sectionsParam(p.section)) out.push_back(&p);
  return out;
}

std::vector<std::string> ModelType::sections() const {
  std::vector<std::string> out;
  for (const ParamSpec* p : keywordParams())
    if (std::find(out.begin(), out.end(), p->section) == out.end()) out.push_back(p->section);
  return out;
}

std::vector<std::string> ModelType::keysOf(const std::string& section) const {
  const std::string base = section.substr(0, section.find('.'));
  std::vector<std::string> out;
  for (const auto& p : params)
    if (p.section == base) out.push_back(p.key);
  return out;
}

void registerModelType(ModelType type) {
  requireComplete(type);
  type = takingColoredNoise(std::move(type));
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  for (const auto& t : r.types) {
    bool clash = named(t, type.name) || t.class_name == type.class_name;
    for (const auto& a : type.aliases) clash = clash || named(t, a);
    if (clash)
      throw InvalidArgument("registerModelType '" + type.name + "' (" + type.class_name +
                            "): the name, an alias or the class name is taken by '" + t.name + "'");
  }
  r.types.push_back(std::move(type));
}

const ModelType* findModelType(const std::string& name) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  for (const auto& t : r.types)
    if (named(t, name)) return &t;
  return nullptr;
}

const ModelType* modelTypeOf(const Model& model) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  for (const auto& t : r.types)
    if (t.owns(model)) return &t;
  return nullptr;
}

std::vector<const ModelType*> modelTypes() {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<const ModelType*> out;
  for (const auto& t : r.types) out.push_back(&t);
  return out;
}

std::string modelTypeNames() {
  std::string out;
  for (const ModelType* t : modelTypes()) out += (out.empty() ? "" : ", ") + t->name;
  return out;
}

}  // namespace gssm
