#include "hexatwist/io/config.hpp"

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <map>
#include <sstream>
#include <vector>

#include "hexatwist/error.hpp"

namespace hexatwist {
namespace {

// Text from the document or a file name as it may appear inside a one-line message: control
// characters escaped, and (if `max` is set) cut at a character boundary after `max` bytes.
std::string one_line(std::string_view s, std::size_t max = std::string_view::npos) {
  std::size_t n = std::min(s.size(), max);
  while (n < s.size() && n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;  // UTF-8 continuation
  std::string out;
  for (const char c : s.substr(0, n)) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n')
      out += "\\n";
    else if (c == '\r')
      out += "\\r";
    else if (c == '\t')
      out += "\\t";
    else if (u < 0x20 || u == 0x7f)
      out += fmt::format("\\x{:02x}", u);
    else
      out += c;
  }
  if (n < s.size()) out += "...";
  return out;
}

// A document value quoted for a message.
std::string quoted(const YAML::Node& n) { return "'" + one_line(n.Scalar(), 40) + "'"; }

// "a list", "a mapping", ... for messages about a value of the wrong kind.
const char* kind(const YAML::Node& n) {
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

Loc loc(const Field& f) { return {f.path, f.at()}; }

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

struct Screw {
  double lead = 0.0;
  double drive_lead = std::numeric_limits<double>::quiet_NaN();  // NaN: the lead (no drive scale)
  Loc drive_lead_at;
  ThreadSense thread = ThreadSense::Right;
  DrivenSide driven = DrivenSide::Base;
  bool thread_given = false;  // thread / driven_side were written (here or in `screw`)
  bool driven_given = false;
  Loc lead_at;  // where the lead came from
};

constexpr const char* kThreadWhat = "thread hand; needed when lead > 0";
constexpr const char* kDrivenWhat = "side whose motor turns the screw; needed when lead > 0";

// Reads lead / thread / driven_side from `n` (the `screw` block or a leg), on top of `s`. The
// `screw` block (top) must give a lead, and a thread and driven side when that lead is > 0.
Screw read_screw(const Reader& r, const Field& n, Screw s, bool top) {
  const Field lead = Reader::child(n, "lead");
  if (top || lead.present()) {
    s.lead = r.number(lead, "screw travel per revolution [m], >= 0; 0 = no twist");
    if (s.lead < 0.0) r.fail(lead.at(), lead.path, fmt::format("expected >= 0 m, got {}", s.lead));
    s.lead_at = loc(lead);
    s.drive_lead = std::numeric_limits<double>::quiet_NaN();  // a leg's own lead has its own drive lead
  }
  // The lead the drive converts lengths with (an identification's contract, theory §4).
  if (const Field drive = Reader::child(n, "drive_lead"); drive.present()) {
    s.drive_lead = r.number(drive, "lead the drive converts lengths to motor angles with [m], > 0");
    if (!(s.drive_lead > 0.0)) r.fail(drive.at(), drive.path, fmt::format("expected > 0 m, got {}", s.drive_lead));
    s.drive_lead_at = loc(drive);
  }
  const bool need_sense = top && s.lead > 0.0;
  const Field thread = Reader::child(n, "thread");
  if (need_sense || thread.present()) {
    s.thread = r.word(thread, kThreadWhat, {"right", "left"}) == "right" ? ThreadSense::Right : ThreadSense::Left;
    s.thread_given = true;
  }
  const Field driven = Reader::child(n, "driven_side");
  if (need_sense || driven.present()) {
    s.driven = r.word(driven, kDrivenWhat, {"base", "platform"}) == "base" ? DrivenSide::Base : DrivenSide::Platform;
    s.driven_given = true;
  }
  // A leg with its own lead > 0 needs a thread and driven side, its own or the screw block's.
  if (!top && s.lead > 0.0) {
    if (!s.thread_given) r.require(thread, fmt::format("right or left ({}; or set screw.thread)", kThreadWhat));
    if (!s.driven_given) r.require(driven, fmt::format("base or platform ({}; or set screw.driven_side)", kDrivenWhat));
  }
  return s;
}

void read_extras(const Reader& r, const Field& top, Locations& locs, ConfigSpec& out);

// Where each document of a YAML text starts, from the parser's events (no nodes are built).
class DocumentStarts : public YAML::EventHandler {
 public:
  std::vector<YAML::Mark> marks;
  void OnDocumentStart(const YAML::Mark& mark) override { marks.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

// yaml-cpp 0.7 reads some malformed text (a ',' where a document starts, as in ",a: 1") as an
// endless series of empty documents, so that LoadAll never returns and fills the memory. A
// document that starts where the one before it started has read nothing: the text is stuck there.
void check_documents_advance(const Reader& r, std::string_view yaml_text) {
  std::istringstream in{std::string(yaml_text)};
  YAML::Parser parser(in);
  DocumentStarts starts;
  while (parser.HandleNextDocument(starts)) {
    const std::vector<YAML::Mark>& m = starts.marks;
    if (m.size() >= 2 && m[m.size() - 1].pos == m[m.size() - 2].pos) {
      const auto pos = static_cast<std::size_t>(std::max(0, m.back().pos));
      throw Error(fmt::format("{}: YAML syntax error: unexpected '{}'", r.where(m.back()),
                              one_line(yaml_text.substr(std::min(pos, yaml_text.size()), 1))));
    }
  }
}

ModelSpec parse(std::string_view yaml_text, std::string_view source, Locations& locs, ConfigSpec& extras) {
  const Reader r(source);
  std::vector<YAML::Node> docs;
  try {
    check_documents_advance(r, yaml_text);
    docs = YAML::LoadAll(std::string(yaml_text));
  } catch (const YAML::Exception& e) {
    throw Error(fmt::format("{}: YAML syntax error: {}", r.where(e.mark), one_line(e.msg)));
  }
  if (docs.size() > 1)
    throw Error(fmt::format("{}: expected one YAML document, found {} (remove the extra '---')",
                            r.where(docs[1].Mark()), docs.size()));
  const YAML::Node root = docs.empty() ? YAML::Node() : docs[0];
  if (root.IsNull())
    throw Error(
        fmt::format("{}:1:1: empty document; expected a mapping with 'symmetric' or 'legs', 'screw' and 'limits'",
                    one_line(source)));
  if (!root.IsMap())
    throw Error(
        fmt::format("{}: expected a mapping with 'symmetric' or 'legs', 'screw' and 'limits' at top level, got {}",
                    r.where(root.Mark()), kind(root)));
  const Field top{root, "", root.Mark()};
  r.only_keys(top, {"name", "symmetric", "legs", "home_height", "screw", "length_offsets", "home_commands", "limits",
                    "observation_point", "pivot", "servo", "load", "simulation", "study", "mechanism"});

  ModelSpec spec;
  const Field name = Reader::child(top, "name");
  if (name.present() && !name.node.IsScalar() && !name.node.IsNull())
    r.fail(name.at(), name.path, fmt::format("expected text, got {}", kind(name.node)));
  spec.name = name.present() && name.node.IsScalar() ? name.node.Scalar() : std::string(source);

  const Field screw_f = Reader::child(top, "screw");
  r.require_map(screw_f, "lead, thread, driven_side");
  r.only_keys(screw_f, {"lead", "thread", "driven_side", "drive_lead"});
  const Screw screw = read_screw(r, screw_f, Screw{}, true);

  const Field sym = Reader::child(top, "symmetric");
  const Field legs = Reader::child(top, "legs");
  constexpr const char* kOneOf = "give exactly one of 'symmetric' (Ra, Rb, da, db, H) or 'legs' (six explicit legs)";
  if (sym.present() && legs.present()) {
    const bool legs_later = legs.key.line > sym.key.line;
    const Field& second = legs_later ? legs : sym;
    const Field& first = legs_later ? sym : legs;
    r.fail(second.key, second.path,
           fmt::format("not allowed together with '{}' (line {}); {}", first.path, first.key.line + 1, kOneOf));
  }
  if (!sym.present() && !legs.present()) throw Error(fmt::format("{}: {}; found neither", r.where(top.key), kOneOf));

  if (sym.present()) {
    r.require_map(sym, "Ra, Rb, da, db, H");
    r.only_keys(sym, {"Ra", "Rb", "da", "db", "H", "base_pair_angles_deg", "platform_pair_angles_deg"});
    if (const Field hh = Reader::child(top, "home_height"); hh.present())
      r.fail(hh.key, hh.path, "not allowed with 'symmetric' (use symmetric.H)");
    auto length = [&](const char* key, const char* what, bool zero_ok) {
      const Field f = Reader::child(sym, key);
      const double v = r.number(f, what);
      if (zero_ok ? v < 0.0 : v <= 0.0)
        r.fail(f.at(), f.path, fmt::format("expected {} 0 m, got {}", zero_ok ? ">=" : ">", v));
      return v;
    };
    SymmetricSpec ss;
    ss.Ra = length("Ra", "platform joint-pair radius [m]", false);
    ss.Rb = length("Rb", "base joint-pair radius [m]", false);
    ss.da = length("da", "platform joint spacing in a pair [m]", true);
    ss.db = length("db", "base joint spacing in a pair [m]", true);
    ss.H = length("H", "home height of the platform joints above the base joints [m]", false);
    auto angles = [&](const char* key, std::array<double, 3>& out) {
      const Field f = Reader::child(sym, key);
      if (!f.present()) return;
      const Vector3d a = r.vec3(f, "three pair-centre angles [deg]");
      for (int i = 0; i < 3; ++i) out[static_cast<std::size_t>(i)] = deg2rad(a[i]);
    };
    angles("base_pair_angles_deg", ss.base_pair_angles);
    angles("platform_pair_angles_deg", ss.platform_pair_angles);
    spec.legs = symmetric_legs(ss);
    spec.home_height = ss.H;
    spec.observation_P = Vector3d(ss.Ra, 0.0, 0.0);
    for (LegSpec& leg : spec.legs) {
      leg.lead = screw.lead;
      leg.thread = screw.thread;
      leg.driven = screw.driven;
      leg.drive_lead = screw.drive_lead;
    }
    // A leg's lead is the screw block's: its errors point at screw.lead.
    for (int i = 0; i < kLegs; ++i) {
      locs[fmt::format("leg {}: lead", i + 1)] = screw.lead_at;
      locs[fmt::format("leg {}: drive_lead", i + 1)] = screw.drive_lead_at;
    }
    // The legs are derived from the whole block: their errors point at it.
    locs["legs"] = Loc{"symmetric", sym.key};
    locs["home_height"] = loc(Reader::child(sym, "H"));
  } else {
    const Field hh = Reader::child(top, "home_height");
    spec.home_height = r.number(hh, "height of the platform frame above the base frame at home [m]");
    locs["home_height"] = loc(hh);
    if (!legs.node.IsSequence() || legs.node.size() != kLegs)
      r.fail(legs.key, legs.path,
             fmt::format("expected a list of exactly 6 legs, got {}",
                         legs.node.IsSequence() ? fmt::format("{}", legs.node.size()) : std::string(kind(legs.node))));
    locs["legs"] = Loc{"legs", legs.key};
    double farthest = -1.0;
    for (int i = 0; i < kLegs; ++i) {
      const Field n = Reader::item(legs, static_cast<std::size_t>(i), fmt::format("legs[{}] (leg {})", i, i + 1));
      if (!n.node.IsMap())
        r.fail(n.at(), n.path,
               fmt::format("expected a mapping with base, platform, base_axis, platform_axis, got {}", kind(n.node)));
      r.only_keys(n, {"base", "platform", "base_axis", "platform_axis", "lead", "thread", "driven_side", "drive_lead"});
      const std::string who = fmt::format("leg {}", i + 1);
      locs[who] = Loc{n.path, n.key};
      LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
      const Field base = Reader::child(n, "base");
      leg.base_B = r.vec3(base, "base joint x, y, z [m, base frame]");
      locs[who + ": base"] = loc(base);
      const Field platform = Reader::child(n, "platform");
      leg.platform_P = r.vec3(platform, "platform joint x, y, z [m, platform frame]");
      locs[who + ": platform"] = loc(platform);
      const Screw ls = read_screw(r, n, screw, false);
      leg.lead = ls.lead;
      leg.thread = ls.thread;
      leg.driven = ls.driven;
      leg.drive_lead = ls.drive_lead;
      locs[who + ": lead"] = ls.lead_at;
      locs[who + ": drive_lead"] = ls.drive_lead_at;
      const bool need_axes = leg.lead > 0.0;
      const Field base_axis = Reader::child(n, "base_axis");
      if (need_axes || base_axis.present()) {
        leg.axis_base_B = r.vec3(base_axis, "base U-joint fixed axis x, y, z, base frame; needed when lead > 0");
        locs[who + ": base_axis"] = loc(base_axis);
      }
      const Field platform_axis = Reader::child(n, "platform_axis");
      if (need_axes || platform_axis.present()) {
        leg.axis_platform_P =
            r.vec3(platform_axis, "platform U-joint fixed axis x, y, z, platform frame; needed when lead > 0");
        locs[who + ": platform_axis"] = loc(platform_axis);
      }
      // Default observation point: the platform joint farthest from the platform centre.
      const double rho = leg.platform_P.head<2>().norm();
      if (rho > farthest) {
        farthest = rho;
        spec.observation_P = leg.platform_P;
      }
    }
  }

  // The legs' zero errors (identification's estimate), one list for either layout.
  if (const Field offsets = Reader::child(top, "length_offsets"); offsets.present()) {
    constexpr const char* kWhat = "real minus motor-side length at zero twist of legs 1..6 [m]";
    if (!offsets.node.IsSequence() || offsets.node.size() != kLegs)
      r.fail(offsets.at(), offsets.path,
             fmt::format("expected a list of 6 numbers ({}), got {}", kWhat,
                         offsets.node.IsSequence() ? fmt::format("{} numbers", offsets.node.size())
                                                   : std::string(kind(offsets.node))));
    for (int i = 0; i < kLegs; ++i) {
      const Field f = Reader::item(offsets, static_cast<std::size_t>(i), fmt::format("{}[{}]", offsets.path, i));
      spec.legs[static_cast<std::size_t>(i)].length_offset = r.number(f, kWhat);
      locs[fmt::format("leg {}: length_offset", i + 1)] = loc(f);
    }
  }

  // The drives' reference (an identification's contract, theory §4), one list for either layout.
  if (const Field homes = Reader::child(top, "home_commands"); homes.present()) {
    constexpr const char* kWhat = "motor-side length each drive reads at its reference (homing), legs 1..6 [m]";
    if (!homes.node.IsSequence() || homes.node.size() != kLegs)
      r.fail(homes.at(), homes.path,
             fmt::format("expected a list of 6 numbers ({}), got {}", kWhat,
                         homes.node.IsSequence() ? fmt::format("{} numbers", homes.node.size())
                                                 : std::string(kind(homes.node))));
    for (int i = 0; i < kLegs; ++i) {
      const Field f = Reader::item(homes, static_cast<std::size_t>(i), fmt::format("{}[{}]", homes.path, i));
      spec.legs[static_cast<std::size_t>(i)].home_command = r.number(f, kWhat);
      locs[fmt::format("leg {}: home_command", i + 1)] = loc(f);
    }
  }

  const Field lim = Reader::child(top, "limits");
  r.require_map(lim, "length_min, length_max [m]");
  r.only_keys(lim, {"length_min", "length_max", "bend_max_deg", "singularity_margin_deg", "jacobian_condition_max"});
  const Field lmin = Reader::child(lim, "length_min"), lmax = Reader::child(lim, "length_max");
  const Field bend = Reader::child(lim, "bend_max_deg"), margin = Reader::child(lim, "singularity_margin_deg");
  spec.limits.length_min = r.number(lmin, "shortest leg [m]");
  spec.limits.length_max = r.number(lmax, "longest leg [m]");
  spec.limits.bend_max = deg2rad(r.number_or(bend, "largest U-joint bend [deg]", 30.0));
  spec.limits.singularity_margin = deg2rad(r.number_or(margin, "smallest leg-to-axis angle [deg]", 5.0));
  const Field condition = Reader::child(lim, "jacobian_condition_max");
  spec.limits.jacobian_condition_max =
      r.number_or(condition, "largest condition number of the Jacobian [-]", kDefaultJacobianConditionMax);
  locs["limits.length_min"] = loc(lmin);
  locs["limits.length_max"] = loc(lmax);
  locs["limits.bend_max"] = loc(bend);
  locs["limits.singularity_margin"] = loc(margin);
  locs["limits.jacobian_condition_max"] = loc(condition);

  const Field obs = Reader::child(top, "observation_point"), pivot = Reader::child(top, "pivot");
  if (obs.present()) spec.observation_P = r.vec3(obs, "point x, y, z [m, platform frame]");
  if (pivot.present()) spec.pivot_P = r.vec3(pivot, "point x, y, z [m, platform frame]");
  locs["observation_point"] = loc(obs);
  locs["pivot"] = loc(pivot);
  read_extras(r, top, locs, extras);
  return spec;
}

// Optional sections; every key has a default (rig.hpp, study.hpp). Sign and range errors are
// caught here, where the units the file uses (rpm, Hz, deg) are known.
void read_extras(const Reader& r, const Field& top, Locations& locs, ConfigSpec& out) {
  enum Range { Positive, NonNegative };
  const auto section = [&](const char* key, std::initializer_list<const char*> keys) {
    const Field f = Reader::child(top, key);
    if (f.present()) {
      r.require_map(f, "a mapping of settings");
      r.only_keys(f, keys);
    }
    return f;
  };
  // Reads `key` of `sec` into `value` times `scale` if present; `field` is the name the library's
  // validation uses in its messages.
  const auto num = [&](const Field& sec, const char* key, const char* what, Range range, double& value,
                       double scale = 1.0, const char* field = nullptr) {
    if (!sec.present()) return;
    const Field f = Reader::child(sec, key);
    if (!f.present()) return;
    const double v = r.number(f, what);
    if (range == Positive && !(v > 0.0)) r.fail(f.at(), f.path, fmt::format("expected > 0 ({}), got {}", what, v));
    if (range == NonNegative && v < 0.0) r.fail(f.at(), f.path, fmt::format("expected >= 0 ({}), got {}", what, v));
    value = v * scale;
    locs[field != nullptr ? std::string(field) : f.path] = loc(f);
  };
  const auto vec = [&](const Field& sec, const char* key, const char* what, Vector3d& value) {
    if (!sec.present()) return;
    const Field f = Reader::child(sec, key);
    if (!f.present()) return;
    value = r.vec3(f, what);
    locs[f.path] = loc(f);
  };
  constexpr double kRpm = 2.0 * kPi / 60.0;

  ServoSpec& sv = out.rig.servo;
  const Field servo =
      section("servo", {"motor_inertia", "screw_inertia", "viscous_friction", "coulomb_friction", "friction_speed",
                        "torque_time_constant", "torque_limit", "max_speed_rpm", "encoder_counts", "gear_ratio",
                        "pole_frequency_hz", "kp", "ki", "kd", "velocity_feedforward", "acceleration_feedforward",
                        "peak_corner_rpm", "peak_torque_at_max_speed", "continuous_torque"});
  num(servo, "motor_inertia", "rotor inertia [kg m^2]", Positive, sv.motor_inertia);
  num(servo, "screw_inertia", "screw and coupling inertia [kg m^2]", NonNegative, sv.screw_inertia);
  num(servo, "viscous_friction", "at the motor shaft [N m s/rad]", NonNegative, sv.viscous_friction);
  num(servo, "coulomb_friction", "dry friction at the motor shaft [N m]", NonNegative, sv.coulomb_friction);
  num(servo, "friction_speed", "speed over which dry friction changes sign [rad/s]", Positive, sv.friction_speed);
  num(servo, "torque_time_constant", "current-loop lag [s]; 0 = instant", NonNegative, sv.torque_time_constant);
  num(servo, "torque_limit", "peak motor torque [N m]", Positive, sv.torque_limit);
  num(servo, "max_speed_rpm", "motor speed limit [rpm]", Positive, sv.max_speed, kRpm, "servo.max_speed");
  num(servo, "encoder_counts", "counts per motor revolution", Positive, sv.encoder_counts);
  num(servo, "gear_ratio", "motor revolutions per screw revolution", Positive, sv.gear_ratio);
  num(servo, "pole_frequency_hz", "closed-loop pole frequency of the position loop [Hz]", Positive, sv.pole_frequency,
      1.0, "servo.pole_frequency");
  num(servo, "kp", "[N m/rad]; 0 = from pole_frequency_hz", NonNegative, sv.kp);
  num(servo, "ki", "[N m/(rad s)]; 0 = from pole_frequency_hz", NonNegative, sv.ki);
  num(servo, "kd", "[N m s/rad]; 0 = from pole_frequency_hz", NonNegative, sv.kd);
  num(servo, "velocity_feedforward", "fraction of the viscous torque", NonNegative, sv.velocity_feedforward);
  num(servo, "acceleration_feedforward", "fraction of the inertia torque", NonNegative, sv.acceleration_feedforward);
  num(servo, "peak_corner_rpm", "speed up to which the peak torque holds [rpm]", Positive, sv.peak_corner_speed, kRpm,
      "servo.peak_corner_speed");
  num(servo, "peak_torque_at_max_speed", "peak torque left at the maximum speed [N m]", NonNegative,
      sv.peak_torque_at_max_speed);
  num(servo, "continuous_torque", "largest RMS torque [N m]", Positive, sv.continuous_torque);

  LoadSpec& ld = out.rig.load;
  const Field load = section("load", {"mass", "center_of_mass", "inertia", "products_of_inertia", "gravity"});
  num(load, "mass", "platform + payload [kg]", Positive, ld.mass);
  vec(load, "center_of_mass", "x, y, z [m, platform frame]", ld.center_of_mass_P);
  vec(load, "inertia", "principal moments Ixx, Iyy, Izz about the centre of mass [kg m^2]", ld.inertia);
  vec(load, "products_of_inertia", "Ixy, Ixz, Iyz of the inertia tensor about the centre of mass [kg m^2]",
      ld.products);
  num(load, "gravity", "[m/s^2]", NonNegative, ld.gravity);

  MechanismSpec& mc = out.rig.mechanism;
  const Field mech = section("mechanism", {"housing", "rod", "efficiency", "back_efficiency"});
  const auto leg_body = [&](const char* key, LegBodySpec& b) {
    if (!mech.present()) return;
    const Field f = Reader::child(mech, key);
    if (!f.present()) return;
    r.require_map(f, "mass, center, axial_inertia, transverse_inertia");
    r.only_keys(f, {"mass", "center", "axial_inertia", "transverse_inertia"});
    num(f, "mass", "[kg]", NonNegative, b.mass);
    if (const Field c = Reader::child(f, "center"); c.present()) {
      b.center = r.number(c, "distance of the centre of mass from the body's U-joint along the leg [m]");
      locs[c.path] = loc(c);
    }
    num(f, "axial_inertia", "about the leg axis [kg m^2]", NonNegative, b.axial_inertia);
    num(f, "transverse_inertia", "across the leg through the centre of mass [kg m^2]", NonNegative,
        b.transverse_inertia);
  };
  leg_body("housing", mc.housing);
  leg_body("rod", mc.rod);
  num(mech, "efficiency", "screw efficiency, motor driving the load, in (0, 1]", Positive, mc.efficiency);
  num(mech, "back_efficiency", "screw efficiency, load driving the motor, in (0, 1]", Positive, mc.back_efficiency);

  SimulationSpec& sm = out.rig.simulation;
  const Field sim = section("simulation", {"control_rate_hz", "plant_step"});
  num(sim, "control_rate_hz", "servo rate [Hz]", Positive, sm.control_rate, 1.0, "simulation.control_rate");
  num(sim, "plant_step", "largest plant integration step [s]", Positive, sm.plant_step);

  StudySpec& st = out.study;
  const Field study = section("study", {"linear_amplitude", "angular_amplitude_deg", "linear", "angular_deg", "dwell"});
  num(study, "linear_amplitude", "translation sweep amplitude [m]", Positive, st.linear_amplitude);
  num(study, "angular_amplitude_deg", "rotation sweep amplitude [deg]", Positive, st.angular_amplitude, deg2rad(1.0));
  num(study, "dwell", "rest before, between and after the moves [s]", NonNegative, st.dwell);
  const auto limits = [&](const char* key, const char* unit, double scale, MotionLimits& m) {
    if (!study.present()) return;
    const Field f = Reader::child(study, key);
    if (!f.present()) return;
    r.require_map(f, "velocity, acceleration, jerk");
    r.only_keys(f, {"velocity", "acceleration", "jerk"});
    num(f, "velocity", fmt::format("largest speed [{}/s]", unit).c_str(), Positive, m.velocity, scale);
    num(f, "acceleration", fmt::format("largest acceleration [{}/s^2]", unit).c_str(), Positive, m.acceleration, scale);
    num(f, "jerk", fmt::format("largest jerk [{}/s^3]", unit).c_str(), Positive, m.jerk, scale);
  };
  limits("linear", "m", 1.0, st.linear);
  limits("angular_deg", "deg", deg2rad(1.0), st.angular);
}

// Turns a Model error into a located one. Model messages are "field: what", with field one of
// home_height, limits.<x>, observation_point, pivot, legs, "leg N" or "leg N: <sub>" (see
// src/kinematics/model.cpp); the field is replaced by the place in the document it came from.
std::string locate(const Reader& r, const Locations& locs, std::string_view source, std::string_view msg) {
  const std::size_t colon = msg.find(": ");
  if (colon == std::string_view::npos) return fmt::format("{}: {}", one_line(source), msg);
  std::string field(msg.substr(0, colon));
  std::string_view what = msg.substr(colon + 2);
  std::string sub;
  const bool leg_field = field.starts_with("leg ");
  if (leg_field)
    for (const char* s :
         {"base_axis", "platform_axis", "base", "platform", "lead", "length_offset", "drive_lead", "home_command"}) {
      const std::size_t n = std::strlen(s);
      if (what.starts_with(s) && what.substr(n).starts_with(": ")) {
        sub = s;
        what = what.substr(n + 2);
        break;
      }
    }
  const auto found = [&](const std::string& key) { return locs.find(key); };
  if (auto it = found(sub.empty() ? field : field + ": " + sub); it != locs.end())
    return fmt::format("{}: field '{}': {}", r.where(it->second.mark), it->second.path, what);
  if (leg_field) {
    if (auto it = found(field); it != locs.end())
      return fmt::format("{}: field '{}': {}", r.where(it->second.mark), Reader::join(it->second.path, sub), what);
    // A derived (symmetric) leg: point at the block and keep the leg in the message.
    if (auto it = found("legs"); it != locs.end())
      return fmt::format("{}: field '{}': {}", r.where(it->second.mark), it->second.path, msg);
  }
  return fmt::format("{}: {}", one_line(source), msg);
}

}  // namespace

ModelSpec parse_model_spec(std::string_view yaml_text, std::string_view source) {
  Locations locs;
  ConfigSpec extras;
  return parse(yaml_text, source, locs, extras);
}

ConfigSpec parse_config_spec(std::string_view yaml_text, std::string_view source) {
  Locations locs;
  ConfigSpec out;
  out.rig.model = parse(yaml_text, source, locs, out);
  return out;
}

Config load_config(std::string_view yaml_text, std::string_view source) {
  Locations locs;
  ConfigSpec spec;
  spec.rig.model = parse(yaml_text, source, locs, spec);
  try {
    Config config{Rig(spec.rig), spec.study};
    seed_tests(spec.study);  // the study's numbers are checked where they are used; fail early here
    return config;
  } catch (const Error& e) {
    throw Error(locate(Reader(source), locs, source, e.what()));
  }
}

Model load_model(std::string_view yaml_text, std::string_view source) {
  Locations locs;
  ConfigSpec extras;
  const ModelSpec spec = parse(yaml_text, source, locs, extras);
  try {
    return Model(spec);
  } catch (const Error& e) {
    throw Error(locate(Reader(source), locs, source, e.what()));
  }
}

namespace {
constexpr const char* kSeedSource = "seed platform (embedded configs/seed.yaml)";
}

Model default_model() { return load_model(seed_config_yaml(), kSeedSource); }

Config default_config() { return load_config(seed_config_yaml(), kSeedSource); }

}  // namespace hexatwist
