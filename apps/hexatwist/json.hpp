// SPDX-License-Identifier: BSD-3-Clause
// A minimal JSON writer for the CLI's --json output (numbers round-trip exactly; NaN/inf become
// null, which the CLI never emits for a valid result).
#pragma once

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "hexatwist/types.hpp"

namespace hexatwist::cli {

class JsonWriter {
 public:
  JsonWriter& begin_object() { return open('{', true); }
  /// A document: an object whose first field names its schema and version (schemas.hpp).
  JsonWriter& begin_document(std::string_view schema) {
    begin_object();
    key("schema");
    return value(schema);
  }
  JsonWriter& end_object() { return close('}'); }
  /// An array; `multiline` puts each element on its own line (for arrays of objects).
  JsonWriter& begin_array(bool multiline = false) { return open('[', multiline); }
  JsonWriter& end_array() { return close(']'); }

  JsonWriter& key(std::string_view k) {
    separator();
    string(k);
    out_ += ": ";
    after_key_ = true;
    return *this;
  }
  JsonWriter& value(double v) {
    separator();
    out_ += std::isfinite(v) ? fmt::format("{}", v) : "null";
    return *this;
  }
  JsonWriter& value(int v) {
    separator();
    out_ += fmt::format("{}", v);
    return *this;
  }
  JsonWriter& value(std::uint64_t v) {
    separator();
    out_ += fmt::format("{}", v);
    return *this;
  }
  JsonWriter& value(bool v) {
    separator();
    out_ += v ? "true" : "false";
    return *this;
  }
  JsonWriter& value(std::string_view v) {
    separator();
    string(v);
    return *this;
  }
  JsonWriter& value(const char* v) { return value(std::string_view(v)); }
  JsonWriter& null() {
    separator();
    out_ += "null";
    return *this;
  }
  template <class Vec>
  JsonWriter& vector(const Vec& v) {
    begin_array();
    for (Eigen::Index i = 0; i < v.size(); ++i) value(static_cast<double>(v[i]));
    return end_array();
  }
  /// Shorthand for key(k).value(v).
  template <class T>
  JsonWriter& field(std::string_view k, const T& v) {
    key(k);
    return value(v);
  }
  /// key(k) and the number `v`, or null where there is none (`known` false, or v not finite).
  JsonWriter& number_or_null(std::string_view k, double v, bool known = true) {
    key(k);
    return known && std::isfinite(v) ? value(v) : null();
  }

  std::string str() const { return out_ + "\n"; }

 private:
  struct Level {
    bool multiline;
    bool empty = true;
  };

  JsonWriter& open(char c, bool multiline) {
    separator();
    out_ += c;
    stack_.push_back({multiline});
    return *this;
  }
  JsonWriter& close(char c) {
    const Level l = stack_.back();
    stack_.pop_back();
    if (l.multiline && !l.empty) newline();
    out_ += c;
    return *this;
  }
  void separator() {
    if (after_key_) {
      after_key_ = false;
      return;
    }
    if (stack_.empty()) return;
    Level& l = stack_.back();
    if (!l.empty) out_ += l.multiline ? "," : ", ";
    l.empty = false;
    if (l.multiline) newline();
  }
  void newline() { out_ += "\n" + std::string(2 * stack_.size(), ' '); }
  void string(std::string_view s) {
    out_ += '"';
    for (const char c : s) {
      if (c == '"' || c == '\\') {
        out_ += '\\';
        out_ += c;
      } else if (static_cast<unsigned char>(c) < 0x20) {
        out_ += fmt::format("\\u{:04x}", static_cast<int>(c));
      } else {
        out_ += c;
      }
    }
    out_ += '"';
  }

  std::string out_;
  std::vector<Level> stack_;
  bool after_key_ = false;
};

}  // namespace hexatwist::cli
