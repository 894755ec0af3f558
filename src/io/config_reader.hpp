// SPDX-License-Identifier: BSD-3-Clause
// Internal: the YAML reader of the configuration (src/io/config.cpp, config_sections.cpp): fields
// with their place in the document, and messages "source:line:column: field 'x.y': what".
#pragma once

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>

#include "hexatwist/error.hpp"
#include "hexatwist/io/config.hpp"
#include "motion/csv.hpp"

namespace hexatwist::config_detail {

// Text from the document or a file name as it may appear inside a one-line message: control
// characters escaped, and (if `max` is set) cut at a character boundary after `max` bytes.
inline std::string one_line(std::string_view s, std::size_t max = std::string_view::npos) {
  return detail::printable(s, max);
}

// A document value quoted for a message.
inline std::string quoted(const YAML::Node& n) { return fmt::format("'{}'", one_line(n.Scalar(), 40)); }

// "a list", "a mapping", ... for messages about a value of the wrong kind.
inline const char* kind(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a mapping";
    case YAML::NodeType::Null:
      return "nothing";
    default:
      return "a scalar";
  }
}

// A place in the document: the node (undefined if its key is absent), its dotted path for
// messages, and the mark of the key that introduces it (of the enclosing block if absent).
// Never assign a Field: assigning a yaml-cpp node copies content, and throws for an absent one.
struct Field {
  YAML::Node node;
  std::string path;
  YAML::Mark key;

  bool present() const { return node.IsDefined(); }
  // Where to point for an error about the value: a scalar's own position, else its key's
  // (yaml-cpp marks an empty value at the next key and a block collection at its first entry).
  YAML::Mark at() const { return present() && node.IsScalar() ? node.Mark() : key; }
};

// Where a value that the Model validates came from, to turn a Model error into a located one.
struct Loc {
  std::string path;
  YAML::Mark mark;
};
using Locations = std::map<std::string, Loc>;

inline Loc loc(const Field& f) { return {f.path, f.at()}; }

// Reads one YAML document; every error names source:line:column and the dotted field path.
class Reader {
 public:
  explicit Reader(std::string_view source) : source_(one_line(source)) {}

  [[noreturn]] void fail(const YAML::Mark& at, const std::string& field, const std::string& msg) const {
    throw Error(fmt::format("{}: field '{}': {}", where(at), field, msg));
  }

  std::string where(const YAML::Mark& m) const {
    if (m.is_null()) return source_;
    return fmt::format("{}:{}:{}", source_, m.line + 1, m.column + 1);
  }

  // The value under `key` of the mapping `parent` (absent or not).
  static Field child(const Field& parent, const char* key) {
    const YAML::Node& map = parent.node;
    YAML::Mark mark = parent.key;
    for (const auto& kv : map)
      if (kv.first.IsScalar() && kv.first.Scalar() == key) {
        mark = kv.first.Mark();
        break;
      }
    return Field{map[key], join(parent.path, key), mark};
  }

  // Entry `i` of the list `seq`.
  static Field item(const Field& seq, std::size_t i, std::string path) {
    const YAML::Node n = seq.node[i];
    return Field{n, std::move(path), n.IsNull() ? seq.key : n.Mark()};
  }

  void require(const Field& f, std::string_view what) const {
    if (!f.present()) fail(f.key, f.path, fmt::format("missing; expected {}", what));
  }

  void require_map(const Field& f, std::string_view what) const {
    require(f, what);
    if (!f.node.IsMap()) fail(f.at(), f.path, fmt::format("expected a mapping ({}), got {}", what, kind(f.node)));
  }

  // Rejects keys outside `allowed` (typos must not pass silently) and keys given twice (yaml-cpp
  // would silently keep the first).
  void only_keys(const Field& map, std::initializer_list<const char*> allowed) const {
    std::map<std::string, int> seen;
    for (const auto& kv : map.node) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string();
      const std::string shown = kv.first.IsScalar() ? one_line(key, 40) : std::string("<") + kind(kv.first) + ">";
      bool ok = false;
      for (const char* a : allowed) ok = ok || key == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
        fail(kv.first.Mark(), join(map.path, shown), fmt::format("unknown key; expected one of: {}", list));
      }
      if (const auto [it, fresh] = seen.emplace(key, kv.first.Mark().line + 1); !fresh)
        fail(kv.first.Mark(), join(map.path, key), fmt::format("given twice (first on line {})", it->second));
    }
  }

  double number(const Field& f, std::string_view what) const {
    require(f, what);
    if (f.node.IsNull()) fail(f.at(), f.path, fmt::format("no value; expected a number ({})", what));
    if (!f.node.IsScalar()) fail(f.at(), f.path, fmt::format("expected a number ({}), got {}", what, kind(f.node)));
    double v = 0.0;
    if (!YAML::convert<double>::decode(f.node, v)) {
      // yaml-cpp cannot tell "1.5e999" from "abc": ask strtod whether it is a number too large.
      const std::string& text = f.node.Scalar();
      char* end = nullptr;
      const double parsed = std::strtod(text.c_str(), &end);
      if (!text.empty() && end == text.c_str() + text.size() && std::isinf(parsed))
        fail(f.at(), f.path, fmt::format("number out of range ({}), got {}", what, quoted(f.node)));
      fail(f.at(), f.path, fmt::format("expected a number ({}), got {}", what, quoted(f.node)));
    }
    if (!std::isfinite(v))
      fail(f.at(), f.path, fmt::format("expected a finite number ({}), got {}", what, quoted(f.node)));
    return v;
  }

  double number_or(const Field& f, std::string_view what, double fallback) const {
    return f.present() ? number(f, what) : fallback;
  }

  Vector3d vec3(const Field& f, std::string_view what) const {
    require(f, what);
    if (!f.node.IsSequence() || f.node.size() != 3)
      fail(f.at(), f.path,
           fmt::format("expected a list of three numbers ({}), got {}", what,
                       f.node.IsSequence() ? fmt::format("{} numbers", f.node.size()) : std::string(kind(f.node))));
    Vector3d v;
    for (std::size_t i = 0; i < 3; ++i)
      v[static_cast<Eigen::Index>(i)] = number(item(f, i, fmt::format("{}[{}]", f.path, i)), what);
    return v;
  }

  std::string word(const Field& f, std::string_view what, std::initializer_list<const char*> choices) const {
    std::string list;
    for (const char* c : choices) list += (list.empty() ? "" : " or ") + std::string(c);
    require(f, fmt::format("{} ({})", list, what));
    if (!f.node.IsScalar()) fail(f.at(), f.path, fmt::format("expected {} ({}), got {}", list, what, kind(f.node)));
    for (const char* c : choices)
      if (f.node.Scalar() == c) return c;
    fail(f.at(), f.path, fmt::format("expected {} ({}), got {}", list, what, quoted(f.node)));
  }

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

 private:
  std::string source_;
};

/// Reads the optional sections servo, load, mechanism, simulation and study of `top` into `out`
/// (config_sections.cpp), noting where each value came from in `locs`.
void read_sections(const Reader& r, const Field& top, Locations& locs, ConfigSpec& out);

}  // namespace hexatwist::config_detail
