#pragma once
// Every INI key a reader accepts, with its type, default and meaning, in one
// table per section: the readers refuse any key not in their table, and the
// manual's INI reference is generated from the same tables
// (iniReferenceMarkdown), so the two cannot disagree.
#include <string>
#include <vector>

namespace gssm {
struct ModelType;
}

namespace gssm::io {

struct IniKey {
  std::string key;
  std::string type;           ///< "number", "integer", "flag", "word", "words", "file", "numbers", "matrix", ...
  std::string default_value;  ///< as written in an INI ("" with `required`: none)
  std::string meaning;        ///< one line, with the unit
  bool required = false;
};

struct IniSection {
  std::string name;   ///< "dataset", "model", "channel.<name>"
  std::string about;  ///< what the section is for, one line
  std::vector<IniKey> keys;
};

/// The keys' names, in order (what a reader's requireOnlyKeys takes).
std::vector<std::string> iniKeyNames(const std::vector<IniKey>& keys);

/// [scenario], [dataset], [truth], [learn] and the estimators' sections
/// ([ekf], [smoother], [fixed_lag], [paper_window], [batch]): what every
/// INI may hold besides its model's sections.
std::vector<IniSection> commonIniSections();
/// A registered model type's sections ([model], [prior], its sub-sections,
/// [colored_noise]): its declared parameters, with the defaults its type
/// writes (ModelType::defaults) where it has them.
std::vector<IniSection> modelIniSections(const ModelType& type);
/// The manual's INI reference (Markdown): the common sections, then every
/// registered model type's.
std::string iniReferenceMarkdown();

}  // namespace gssm::io
