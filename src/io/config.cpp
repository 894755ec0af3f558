// SPDX-License-Identifier: BSD-3-Clause
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
#include "hexatwist/io/text_file.hpp"
#include "io/config_reader.hpp"

namespace hexatwist {
namespace {

using namespace config_detail;

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

// The one YAML document of the text: a mapping (errors located in `source`).
YAML::Node load_document(const Reader& r, std::string_view yaml_text, std::string_view source) {
  if (yaml_text.size() > kMaxConfigBytes)
    throw Error(fmt::format("{}: {} bytes of YAML, more than a configuration's {} (1 MiB)",
                            r.where(YAML::Mark::null_mark()), yaml_text.size(), kMaxConfigBytes));
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
  return root;
}

// The `symmetric` layout (the paper's Ra, Rb, da, db, H): six legs derived from the block.
void read_symmetric(const Reader& r, const Field& top, const Field& sym, const Screw& screw, Locations& locs,
                    ModelSpec& spec) {
  r.require_map(sym, "Ra, Rb, da, db, H");
  r.only_keys(sym, {"Ra", "Rb", "da", "db", "H", "base_pair_angles_deg", "platform_pair_angles_deg"});
  if (const Field hh = Reader::child(top, "home_height"); hh.present())
    r.fail(hh.key, hh.path, "not allowed with 'symmetric' (use symmetric.H)");
  // Plausible sizes: up to 100 m, as the Model accepts for every length and coordinate.
  auto length = [&](const char* key, const char* what, bool zero_ok) {
    const Field f = Reader::child(sym, key);
    const double v = r.number(f, what);
    if ((zero_ok ? v < 0.0 : v <= 0.0) || v > 100.0)
      r.fail(f.at(), f.path, fmt::format("expected {} 0 and at most 100 m, got {}", zero_ok ? ">=" : ">", v));
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
    if (a.cwiseAbs().maxCoeff() > 360.0)
      r.fail(f.at(), f.path, fmt::format("expected angles within +-360 deg, got [{}, {}, {}]", a[0], a[1], a[2]));
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
}

// The `legs` layout: six legs given one by one, each may override the screw block.
void read_legs(const Reader& r, const Field& top, const Field& legs, const Screw& screw, Locations& locs,
               ModelSpec& spec) {
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

// A list of six numbers for the legs (`length_offsets`, `home_commands`), one for either layout;
// `field` is the leg field the Model names in its messages.
void read_leg_list(const Reader& r, const Field& top, const char* key, const char* what, double LegSpec::*member,
                   const char* field, Locations& locs, ModelSpec& spec) {
  const Field list = Reader::child(top, key);
  if (!list.present()) return;
  if (!list.node.IsSequence() || list.node.size() != kLegs)
    r.fail(list.at(), list.path,
           fmt::format(
               "expected a list of 6 numbers ({}), got {}", what,
               list.node.IsSequence() ? fmt::format("{} numbers", list.node.size()) : std::string(kind(list.node))));
  for (int i = 0; i < kLegs; ++i) {
    const Field f = Reader::item(list, static_cast<std::size_t>(i), fmt::format("{}[{}]", list.path, i));
    spec.legs[static_cast<std::size_t>(i)].*member = r.number(f, what);
    locs[fmt::format("leg {}: {}", i + 1, field)] = loc(f);
  }
}

// A number for every leg of the `leg_effects` block: one for all six, or a list of six. Non-finite
// values are refused, except infinity where `infinite_ok` (a rigid leg's stiffness: .inf).
void read_effect(const Reader& r, const Field& block, const char* key, const char* what, double LegSpec::*member,
                 bool infinite_ok, Locations& locs, ModelSpec& spec) {
  const Field f = Reader::child(block, key);
  if (!f.present()) return;
  const auto value = [&](const Field& v) {
    if (infinite_ok && v.node.IsScalar()) {
      const std::string& t = v.node.Scalar();
      if (t == ".inf" || t == ".Inf" || t == ".INF" || t == "inf") return std::numeric_limits<double>::infinity();
    }
    return r.number(v, what);
  };
  if (f.node.IsSequence()) {
    if (f.node.size() != kLegs)
      r.fail(f.at(), f.path,
             fmt::format("expected one number or a list of 6 ({}), got {} numbers", what, f.node.size()));
    for (int i = 0; i < kLegs; ++i) {
      const Field item = Reader::item(f, static_cast<std::size_t>(i), fmt::format("{}[{}]", f.path, i));
      spec.legs[static_cast<std::size_t>(i)].*member = value(item);
      locs[fmt::format("leg {}: {}", i + 1, key)] = loc(item);
    }
    return;
  }
  if (!f.node.IsScalar())
    r.fail(f.at(), f.path, fmt::format("expected one number or a list of 6 ({}), got {}", what, kind(f.node)));
  const double v = value(f);
  for (int i = 0; i < kLegs; ++i) {
    spec.legs[static_cast<std::size_t>(i)].*member = v;
    locs[fmt::format("leg {}: {}", i + 1, key)] = loc(f);
  }
}

// `leg_effects`: what the real legs add to the geometry (kinematics/leg_effects.hpp, theory §4b).
void read_leg_effects(const Reader& r, const Field& top, Locations& locs, ModelSpec& spec) {
  const Field block = Reader::child(top, "leg_effects");
  if (!block.present()) return;
  r.require_map(block, "stiffness, play, home_direction, length_expansion, lead_expansion, reference_temperature");
  r.only_keys(block,
              {"stiffness", "play", "home_direction", "length_expansion", "lead_expansion", "reference_temperature"});
  read_effect(r, block, "stiffness", "axial stiffness of each leg [N/m], .inf = rigid", &LegSpec::stiffness, true, locs,
              spec);
  read_effect(r, block, "play", "lost motion along each leg [m]", &LegSpec::play, false, locs, spec);
  read_effect(r, block, "home_direction", "direction of each leg's homing approach, +1 or -1", &LegSpec::home_direction,
              false, locs, spec);
  read_effect(r, block, "length_expansion", "thermal expansion of the length between the joints [1/K]",
              &LegSpec::length_expansion, false, locs, spec);
  read_effect(r, block, "lead_expansion", "thermal expansion of the lead [1/K]", &LegSpec::lead_expansion, false, locs,
              spec);
  const Field t = Reader::child(block, "reference_temperature");
  spec.reference_temperature = r.number_or(t, "temperature at which the geometry holds [degC]", 20.0);
  locs["reference_temperature"] = loc(t);
}

// `limits`, `observation_point` and `pivot`.
void read_limits_and_points(const Reader& r, const Field& top, Locations& locs, ModelSpec& spec) {
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
}

ModelSpec parse(std::string_view yaml_text, std::string_view source, Locations& locs, ConfigSpec& extras) {
  const Reader r(source);
  const YAML::Node root = load_document(r, yaml_text, source);
  const Field top{root, "", root.Mark()};
  r.only_keys(top, {"name", "symmetric", "legs", "home_height", "screw", "length_offsets", "home_commands", "limits",
                    "observation_point", "pivot", "servo", "load", "simulation", "study", "mechanism", "leg_effects"});

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

  if (sym.present())
    read_symmetric(r, top, sym, screw, locs, spec);
  else
    read_legs(r, top, legs, screw, locs, spec);
  // The legs' zero errors (identification's estimate) and the drives' reference (theory §4).
  read_leg_list(r, top, "length_offsets", "real minus motor-side length at zero twist of legs 1..6 [m]",
                &LegSpec::length_offset, "length_offset", locs, spec);
  read_leg_list(r, top, "home_commands", "motor-side length each drive reads at its reference (homing), legs 1..6 [m]",
                &LegSpec::home_command, "home_command", locs, spec);
  read_leg_effects(r, top, locs, spec);
  read_limits_and_points(r, top, locs, spec);
  read_sections(r, top, locs, extras);
  // The legs' static load is that of the load and mechanism sections (defaults where absent), as
  // the Rig's: a model read alone carries it too.
  spec.static_load = static_load_spec(extras.rig.load, extras.rig.mechanism);
  return spec;
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
         {"base_axis", "platform_axis", "base", "platform", "lead", "length_offset", "drive_lead", "home_command",
          "stiffness", "play", "home_direction", "length_expansion", "lead_expansion"}) {
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
    Config config{Rig(spec.rig), spec.study, spec.defaulted};
    check_study(spec.study, config.rig.control_period());
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
