// SPDX-License-Identifier: BSD-3-Clause
// hexatwist workspace: the constant-orientation workspace (its volume, its boundary in slices with the
// limit of every boundary point), the orientation workspace at a position, and maps over a slice
// (design/workspace_*.hpp); summary.json, CSVs and figures, on this machine or a Dask cluster.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>

#include "cli_common.hpp"
#include "cluster.hpp"
#include "design_options.hpp"
#include "figures.hpp"
#include "json.hpp"
#include "output_files.hpp"
#include "progress.hpp"
#include "schemas.hpp"
#include "study_report.hpp"

namespace hexatwist::cli {
namespace {

namespace fs = std::filesystem;

struct WorkspaceCommandOptions {
  ModelOptions model;
  std::string orientation = "0,0,0";
  std::string heights = "-0.4,-0.2,0,0.2,0.4";
  double xz_at = 0.0, yz_at = 0.0;
  double spacing = 0.01;
  std::string position = "0,0,0";
  std::string yaws = "-20,-10,0,10,20";
  double map_height = 0.0;
  double map_spacing = 0.02;
  double cell = 0.0;
  std::string out = "workspace-out";
  std::string scheduler;
  bool json = false;
  bool no_figures = false;
  bool no_csv = false;
};

// A list of numbers "a,b,c" (at least one) for an option.
std::vector<double> number_list(const std::string& text, const std::string& option, const std::string& what) {
  const std::size_t n = static_cast<std::size_t>(std::count(text.begin(), text.end(), ',')) + 1;
  if (n > 64) throw ExitError(kExitBadInput, fmt::format("{}: at most 64 values", option));
  return parse_numbers(text, n, option, what);
}

struct Results {
  Vector3d rpy = Vector3d::Zero();
  WorkspaceVolume volume;
  std::vector<WorkspaceSlice> slices;  // the x-y ones, then x-z, then y-z
  std::size_t xy_slices = 0;
  OrientationWorkspace orientation;
  WorkspaceSlice map_slice;
  WorkspaceMap map;
  int workers = 0;  // Dask workers (0: computed here)
};

// The volume and the map on the cluster; the slices and the orientation workspace (a few tenths of a
// second) here.
void run_on_cluster(const WorkspaceCommandOptions& o, const ModelOptions& mo, Results& r) {
  JsonWriter j;
  j.begin_object();
  j.field("job", "workspace");
  j.field("scheduler", o.scheduler);
  j.key("config");
  if (mo.config.empty())
    j.null();
  else
    j.value(read_text_file(mo.config, "--config", "configuration", kMaxConfigBytes));
  j.key("orientation").vector(r.rpy);
  j.field("cell", o.cell);
  j.field("refine", VolumeOptions{}.refine);
  j.field("step", WorkspaceOptions{}.step);
  j.field("tolerance", WorkspaceOptions{}.tolerance);
  j.field("timeout", 10);
  const MapGrid& g = r.map.grid;
  j.key("map_grid").begin_object();
  j.field("plane", "xy").field("offset", g.offset).field("u0", g.u0).field("u1", g.u1).field("nu", g.nu);
  j.field("v0", g.v0).field("v1", g.v1).field("nv", g.nv);
  j.end_object();
  j.end_object();
  const ClusterArrays a = run_cluster_job(o.scheduler, j.str());
  r.workers = static_cast<int>(cluster_array(a, "workers", 1)[0]);
  r.volume.volume = cluster_array(a, "volume.volume", 1)[0];
  r.volume.coarse_volume = cluster_array(a, "volume.coarse_volume", 1)[0];
  r.volume.error = cluster_array(a, "volume.error", 1)[0];
  r.volume.columns = static_cast<std::uint64_t>(cluster_array(a, "volume.columns", 1)[0]);
  const std::size_t n = g.size();
  r.map.points.assign(n, MapPoint{});
  const auto& status = cluster_array(a, "map.status", n);
  const auto& limit_leg = cluster_array(a, "map.limit_leg", n);
  const auto& max_twist = cluster_array(a, "map.max_twist", n);
  const auto& twist_leg = cluster_array(a, "map.twist_leg", n);
  const auto& max_error = cluster_array(a, "map.max_length_error", n);
  const auto& error_leg = cluster_array(a, "map.length_error_leg", n);
  const auto& condition = cluster_array(a, "map.condition", n);
  const auto& margin = cluster_array(a, "map.margin", n);
  const auto& nearest_status = cluster_array(a, "map.nearest_status", n);
  const auto& nearest_leg = cluster_array(a, "map.nearest_leg", n);
  for (std::size_t k = 0; k < n; ++k) {
    MapPoint& p = r.map.points[k];
    p.status = static_cast<Status>(static_cast<int>(status[k]));
    p.limit.status = p.status;
    p.limit.leg = static_cast<int>(limit_leg[k]);
    p.max_twist = max_twist[k];
    p.twist_leg = static_cast<int>(twist_leg[k]);
    p.max_length_error = max_error[k];
    p.length_error_leg = static_cast<int>(error_leg[k]);
    p.condition = condition[k];
    p.margin = margin[k];
    p.nearest.status = static_cast<Status>(static_cast<int>(nearest_status[k]));
    p.nearest.leg = static_cast<int>(nearest_leg[k]);
  }
}

Results compute(const Model& model, const WorkspaceCommandOptions& o) {
  Results r;
  const std::vector<double> orientation = parse_numbers(o.orientation, 3, "--orientation", "roll,pitch,yaw [deg]");
  r.rpy = Vector3d(deg2rad(orientation[0]), deg2rad(orientation[1]), deg2rad(orientation[2]));
  check_option(o.spacing > 0.0 && o.spacing <= 1.0, "--spacing", o.spacing, "a spacing from 0 to 1 m");
  check_option(o.map_spacing > 0.0 && o.map_spacing <= 1.0, "--map-spacing", o.map_spacing, "a spacing from 0 to 1 m");
  check_cell_option(o.cell);
  check_option(std::isfinite(o.xz_at), "--xz-at", o.xz_at, "a finite y [m]");
  check_option(std::isfinite(o.yz_at), "--yz-at", o.yz_at, "a finite x [m]");
  check_option(std::isfinite(o.map_height), "--map-height", o.map_height, "a finite z [m]");
  const std::vector<double> heights = number_list(o.heights, "--heights", "heights z [m]");
  const std::vector<double> yaws = number_list(o.yaws, "--yaws", "yaws [deg]");
  const std::vector<double> position = parse_numbers(o.position, 3, "--position", "x,y,z [m]");

  WorkspaceOptions search;
  const auto slice = [&](SlicePlane plane, double offset, double spacing) {
    SliceSpec spec;
    spec.plane = plane;
    spec.offset = offset;
    spec.spacing = spacing;
    WorkspaceSlice s;
    if (const Status st = workspace_slice(model, r.rpy, spec, search, s); st != Status::Ok)
      throw ExitError(kExitOutOfLimit, fmt::format("--orientation {}: no position is reachable there ({})",
                                                   printable(o.orientation), describe(st)));
    return s;
  };
  for (const double z : heights) r.slices.push_back(slice(SlicePlane::XY, z, o.spacing));
  r.xy_slices = r.slices.size();
  r.slices.push_back(slice(SlicePlane::XZ, o.xz_at, o.spacing));
  r.slices.push_back(slice(SlicePlane::YZ, o.yz_at, o.spacing));

  OrientationSpec ospec;
  ospec.position = Vector3d(position[0], position[1], position[2]);
  ospec.torsions.clear();
  for (const double y : yaws) ospec.torsions.push_back(deg2rad(y));
  if (orientation_workspace(model, ospec, Strategy::Compensated, r.orientation) != Status::Ok)
    throw ExitError(kExitBadInput, "--yaws, --position: expected finite numbers");

  r.map_slice = slice(SlicePlane::XY, o.map_height, o.map_spacing);
  r.map.grid = map_grid_around(r.map_slice, o.map_spacing);
  r.map.rpy = r.rpy;

  if (!o.scheduler.empty()) {
    run_on_cluster(o, o.model, r);
    VolumeOptions vo;
    vo.cell = o.cell;
    if (volume_grid(model, r.rpy, vo, r.volume.grid) != Status::Ok)
      throw ExitError(kExitOutOfLimit, "--orientation: no position is reachable there");
    return r;
  }
  // On a terminal, a progress line for each of the two parts that grow with the grids.
  VolumeOptions vo;
  vo.cell = o.cell;
  vo.threads = 0;
  VolumeGrid grid;
  Status s = volume_grid(model, r.rpy, vo, grid);
  if (s == Status::Ok) {
    Progress bar(grid.cells(), !o.json);
    vo.progress = [&](std::size_t done, std::size_t total) {
      bar.update(done, fmt::format("volume {}/{} cells", done, total));
    };
    s = workspace_volume(model, r.rpy, vo, r.volume);
  }
  if (s != Status::Ok)
    throw ExitError(kExitOutOfLimit, fmt::format("--orientation {}: no position is reachable there ({})",
                                                 printable(o.orientation), describe(s)));
  Progress bar(static_cast<std::size_t>(r.map.grid.nv), !o.json);
  (void)workspace_map(
      model, r.rpy, r.map.grid, Strategy::Compensated, r.map, 0,
      [&](std::size_t done, std::size_t total) { bar.update(done, fmt::format("map {}/{} rows", done, total)); });
  return r;
}

const char* plane_name(SlicePlane p) { return p == SlicePlane::XY ? "x-y" : p == SlicePlane::XZ ? "x-z" : "y-z"; }
const char* plane_key(SlicePlane p) { return p == SlicePlane::XY ? "xy" : p == SlicePlane::XZ ? "xz" : "yz"; }
const char* fixed_axis(SlicePlane p) { return p == SlicePlane::XY ? "z" : p == SlicePlane::XZ ? "y" : "x"; }
std::string axis_u(SlicePlane p) { return p == SlicePlane::YZ ? "y [m]" : "x [m]"; }
std::string axis_v(SlicePlane p) { return p == SlicePlane::XY ? "y [m]" : "z [m]"; }

// Points of a slice by limit group.
std::array<std::size_t, 5> group_counts(const WorkspaceSlice& s) {
  std::array<std::size_t, 5> n{};
  for (const BoundaryPoint& p : s.boundary)
    if (const int g = limit_group(p.limit.status); g >= 0) ++n[static_cast<std::size_t>(g)];
  return n;
}

std::string summary_json(const Model& model, const WorkspaceCommandOptions& o, const Results& r,
                         const std::vector<std::string>& files) {
  JsonWriter j;
  j.begin_document(schema::kWorkspace);
  j.field("command", "workspace");
  j.field("units", "SI: m, m^2, m^3, rad");
  j.field("config", model_source(o.model));
  j.field("model", model.spec().name);
  j.key("orientation").vector(r.rpy);
  j.field("volume", r.volume.volume);
  j.field("volume_error", r.volume.error);
  j.field("coarse_volume", r.volume.coarse_volume);
  j.field("volume_method",
          "z columns bisected to 1e-9 m over an x-y grid, trapezoidal rule refined at the shadow's edge; the error is "
          "the difference to the grid twice as coarse");
  j.key("grid").begin_object();
  j.field("cell", r.volume.grid.cell);
  j.field("refine", r.volume.grid.refine);
  j.field("nx", r.volume.grid.nx).field("ny", r.volume.grid.ny);
  j.key("box_lower").vector(r.volume.grid.box.lower);
  j.key("box_upper").vector(r.volume.grid.box.upper);
  j.field("columns", r.volume.columns);
  j.end_object();
  j.key("slices").begin_array(true);
  for (const WorkspaceSlice& s : r.slices) {
    j.begin_object();
    j.field("plane", plane_key(s.spec.plane)).field("offset", s.spec.offset).field("spacing", s.spec.spacing);
    j.field("area", s.area).field("boundary_points", static_cast<std::uint64_t>(s.boundary.size()));
    std::map<std::string, std::uint64_t> by;
    for (const BoundaryPoint& p : s.boundary) ++by[std::string(to_string(p.limit.status))];
    j.key("limits").begin_object();
    for (const auto& [k, v] : by) j.field(k, v);
    j.end_object();
    j.end_object();
  }
  j.end_array();
  j.key("orientation_workspace").begin_object();
  j.key("position").vector(r.orientation.spec.position);
  j.field("directions", r.orientation.spec.directions);
  j.key("torsions").begin_array(true);
  for (std::size_t t = 0; t < r.orientation.reach.size(); ++t) {
    const TiltExtremes e = tilt_extremes(r.orientation.reach[t]);
    j.begin_object();
    j.field("torsion", r.orientation.spec.torsions[t]);
    j.field("reached", static_cast<std::uint64_t>(e.reached));
    j.field("smallest_tilt", e.smallest).field("smallest_azimuth", e.smallest_azimuth);
    j.key("smallest_limit");
    write_limit_json(j, e.smallest_limit);
    j.field("largest_tilt", e.largest).field("largest_azimuth", e.largest_azimuth);
    j.end_object();
  }
  j.end_array();
  j.end_object();
  const MapSummary ms = summarize_map(r.map);
  j.key("map").begin_object();
  j.field("plane", "xy").field("offset", r.map.grid.offset);
  j.field("nu", r.map.grid.nu).field("nv", r.map.grid.nv);
  j.field("u0", r.map.grid.u0).field("u1", r.map.grid.u1).field("v0", r.map.grid.v0).field("v1", r.map.grid.v1);
  j.field("inside", static_cast<std::uint64_t>(ms.inside));
  // Every field, null when no node is inside (the extremes are NaN then).
  const auto at = [&](const char* key, std::size_t node) {
    j.key(key);
    if (ms.inside > 0)
      j.vector(map_node_position(r.map.grid, node));
    else
      j.null();
  };
  const auto leg = [&](const char* key, int index) {
    j.key(key);
    if (ms.inside > 0)
      j.value(index + 1);
    else
      j.null();
  };
  j.field("max_twist", ms.max_twist);
  leg("max_twist_leg", ms.max_twist_leg);
  at("max_twist_at", ms.max_twist_node);
  j.field("max_length_error", ms.max_length_error);
  j.field("condition_min", ms.condition_min).field("condition_max", ms.condition_max);
  j.field("margin_min", ms.margin_min);
  at("margin_min_at", ms.margin_min_node);
  j.key("margin_min_limit");
  if (ms.inside > 0)
    j.value(to_string(ms.margin_min_limit.status));
  else
    j.null();
  leg("margin_min_leg", ms.margin_min_limit.leg);
  j.end_object();
  j.key("cluster");
  if (o.scheduler.empty()) {
    j.null();
  } else {
    j.begin_object().field("scheduler", o.scheduler).field("workers", r.workers).end_object();
  }
  j.key("files").begin_array();
  for (const std::string& f : files) j.value(f);
  j.end_array();
  j.end_object();
  return j.str();
}

std::string slices_csv(const Results& r) {
  std::string out =
      "plane,offset_m,u_m,v_m,inside_x_m,inside_y_m,inside_z_m,outside_x_m,outside_y_m,outside_z_m,limit,leg,value,"
      "bound\n";
  auto it = std::back_inserter(out);
  for (const WorkspaceSlice& s : r.slices)
    for (const BoundaryPoint& p : s.boundary)
      fmt::format_to(it, "{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", plane_key(s.spec.plane), s.spec.offset, p.u,
                     p.v, p.inside.x(), p.inside.y(), p.inside.z(), p.outside.x(), p.outside.y(), p.outside.z(),
                     to_string(p.limit.status), p.limit.leg + 1, p.limit.value, p.limit.bound);
  return out;
}

std::string orientation_csv(const Results& r) {
  std::string out = "torsion_rad,azimuth_rad,tilt_rad,limit,leg,value,bound\n";
  auto it = std::back_inserter(out);
  for (std::size_t t = 0; t < r.orientation.reach.size(); ++t)
    for (const TiltReach& x : r.orientation.reach[t])
      fmt::format_to(it, "{},{},{},{},{},{},{}\n", r.orientation.spec.torsions[t], x.azimuth, x.tilt,
                     to_string(x.limit.status), x.limit.leg + 1, x.limit.value, x.limit.bound);
  return out;
}

std::string map_csv(const Results& r) {
  std::string out =
      "x_m,y_m,z_m,status,limit_leg,max_twist_rad,twist_leg,max_length_error_m,length_error_leg,condition,margin,"
      "nearest_limit,nearest_leg\n";
  auto it = std::back_inserter(out);
  for (std::size_t k = 0; k < r.map.points.size(); ++k) {
    const MapPoint& p = r.map.points[k];
    const Vector3d x = map_node_position(r.map.grid, k);
    const bool in = p.status == Status::Ok;
    fmt::format_to(it, "{},{},{},{},{},{},{},{},{},{},{},{},{}\n", x.x(), x.y(), x.z(), to_string(p.status),
                   in ? 0 : p.limit.leg + 1, p.max_twist, p.twist_leg + 1, p.max_length_error, p.length_error_leg + 1,
                   p.condition, p.margin, to_string(in ? p.nearest.status : p.status),
                   (in ? p.nearest.leg : p.limit.leg) + 1);
  }
  return out;
}

// The boundary points of a slice as one series per limit group (the figures' colours).
std::vector<Series> boundary_series(const WorkspaceSlice& s) {
  std::vector<Series> series(5);
  for (std::size_t g = 0; g < 5; ++g) {
    series[g].label = kLimitGroups[g];
    series[g].style = Series::Style::Points;
  }
  for (const BoundaryPoint& p : s.boundary)
    if (const int g = limit_group(p.limit.status); g >= 0) {
      series[static_cast<std::size_t>(g)].x.push_back(p.u);
      series[static_cast<std::size_t>(g)].y.push_back(p.v);
    }
  // Every group keeps its colour from panel to panel; those that bound nothing here say so.
  for (Series& x : series)
    if (x.x.empty()) x.label += " (none here)";
  return series;
}

std::string orientation_label(const Vector3d& rpy) {
  return fmt::format("roll {:g}, pitch {:g}, yaw {:g} deg", rad2deg(rpy[0]), rad2deg(rpy[1]), rad2deg(rpy[2]));
}

std::vector<Figure> figures(const Results& r, const fs::path& dir, const std::string& source) {
  std::vector<Figure> out;
  // The platform named by its source (a file name, or the seed), short enough for a title.
  const std::string at = orientation_label(r.rpy) + ", " + source;
  // One panel per x-y slice, the plane drawn to scale.
  Figure xy{(dir / "slices_xy").string(), fmt::format("Constant-orientation workspace at {}: x-y slices", at), {}};
  for (std::size_t k = 0; k < r.xy_slices; ++k) {
    const WorkspaceSlice& s = r.slices[k];
    Panel p(fmt::format("x-y slice at z = {:+.3f} m: area {:.3f} m^2 (boundary points coloured by the limit met)",
                        s.spec.offset, s.area),
            "x [m]", "y [m]", boundary_series(s));
    p.height = 560;
    p.equal_axes = true;
    xy.panels.push_back(std::move(p));
  }
  out.push_back(std::move(xy));
  Figure vertical{
      (dir / "slices_vertical").string(), fmt::format("Constant-orientation workspace at {}: vertical slices", at), {}};
  for (std::size_t k = r.xy_slices; k < r.slices.size(); ++k) {
    const WorkspaceSlice& s = r.slices[k];
    Panel p(fmt::format("{} slice at {} = {:+.3f} m: area {:.3f} m^2", plane_name(s.spec.plane),
                        fixed_axis(s.spec.plane), s.spec.offset, s.area),
            axis_u(s.spec.plane), axis_v(s.spec.plane), boundary_series(s));
    p.height = 520;
    p.equal_axes = true;
    vertical.panels.push_back(std::move(p));
  }
  out.push_back(std::move(vertical));

  // Orientation workspace: the largest tilt towards each azimuth as a polar curve, one per yaw.
  const Vector3d& pos = r.orientation.spec.position;
  Figure ow{(dir / "orientation").string(),
            fmt::format("Orientation workspace at x {:g}, y {:g}, z {:g} m", pos.x(), pos.y(), pos.z()),
            {}};
  Panel polar("Largest tilt of the platform towards each direction (tilt-and-torsion angles), by yaw",
              "tilt towards +x [deg]", "tilt towards +y [deg]");
  for (std::size_t t = 0; t < r.orientation.reach.size(); ++t) {
    Series s{fmt::format("yaw {:+g} deg", rad2deg(r.orientation.spec.torsions[t])), {}, {}, Series::Style::Solid};
    const auto& row = r.orientation.reach[t];
    for (std::size_t k = 0; k <= row.size(); ++k) {  // closed: the first direction again
      const TiltReach& x = row[k % row.size()];
      s.x.push_back(rad2deg(x.tilt) * std::cos(x.azimuth));
      s.y.push_back(rad2deg(x.tilt) * std::sin(x.azimuth));
    }
    polar.series.push_back(std::move(s));
  }
  polar.height = 640;
  polar.equal_axes = true;
  ow.panels.push_back(std::move(polar));
  out.push_back(std::move(ow));

  // Maps over the x-y slice, the boundary drawn over each.
  const MapGrid& g = r.map.grid;
  std::vector<double> u(static_cast<std::size_t>(g.nu)), v(static_cast<std::size_t>(g.nv));
  for (int i = 0; i < g.nu; ++i) u[static_cast<std::size_t>(i)] = g.u(i);
  for (int j = 0; j < g.nv; ++j) v[static_cast<std::size_t>(j)] = g.v(j);
  Series outline{"workspace boundary", {}, {}, Series::Style::Points};
  for (const BoundaryPoint& p : r.map_slice.boundary) outline.x.push_back(p.u), outline.y.push_back(p.v);
  const auto map_panel = [&](const std::string& title, const std::string& label, auto value,
                             std::vector<std::string> categories = {}) {
    Panel p(title, "x [m]", "y [m]", {outline});
    HeatMap m{u, v, {}, label, std::move(categories)};
    for (const MapPoint& x : r.map.points) m.values.push_back(x.status == Status::Ok ? value(x) : NAN);
    p.map = std::move(m);
    p.height = 560;
    p.equal_axes = true;
    return p;
  };
  const std::vector<std::string> legs{"leg 1", "leg 2", "leg 3", "leg 4", "leg 5", "leg 6"};
  Figure twist{
      (dir / "map_twist").string(), fmt::format("Twist over the x-y slice at z = {:+.3f} m ({})", g.offset, at), {}};
  twist.panels.push_back(map_panel("Largest |twist| over the legs", "largest |twist| [deg]",
                                   [](const MapPoint& x) { return rad2deg(x.max_twist); }));
  twist.panels.push_back(map_panel(
      "The leg with the largest |twist|", "leg", [](const MapPoint& x) { return x.twist_leg + 1.0; }, legs));
  twist.panels.push_back(map_panel("Largest |length error| (Eq. 10) over the legs", "largest |length error| [mm]",
                                   [](const MapPoint& x) { return 1e3 * x.max_length_error; }));
  out.push_back(std::move(twist));
  Figure dexterity{(dir / "map_dexterity").string(),
                   fmt::format("Dexterity and margins over the x-y slice at z = {:+.3f} m ({})", g.offset, at),
                   {}};
  dexterity.panels.push_back(map_panel("Condition number of the motor-side Jacobian (1 is isotropic)",
                                       "condition number [-]", [](const MapPoint& x) { return x.condition; }));
  dexterity.panels.push_back(map_panel("Margin to the nearest limit: share of its range left (0 on the limit)",
                                       "margin [-]", [](const MapPoint& x) { return x.margin; }));
  dexterity.panels.push_back(map_panel("The nearest limit", "nearest limit",
                                       [](const MapPoint& x) { return limit_group(x.nearest.status) + 1.0; },
                                       {"shortest leg", "longest leg", "U-joint bend", "U-joint sing.", "condition"}));
  out.push_back(std::move(dexterity));
  return out;
}

std::string text_report(const Model& model, const WorkspaceCommandOptions& o, const Results& r,
                        const std::string& defaults) {
  std::string out =
      fmt::format("hexatwist workspace on {}: {}{}\n", model_source(o.model), model.spec().name, defaults);
  out += fmt::format(
      "orientation: {}{}\n", orientation_label(r.rpy),
      r.workers > 0 ? fmt::format("; volume and map on {} Dask workers ({})", r.workers, printable(o.scheduler)) : "");
  out += fmt::format("volume: {:.4f} m^3 (stated error {:.4f} m^3, {:.2f} %; grid {:.1f} mm, {} columns)\n",
                     r.volume.volume, r.volume.error, 100.0 * r.volume.error / r.volume.volume,
                     1e3 * r.volume.grid.cell, r.volume.columns);
  out += "slices: area, and the share of boundary points each limit bounds\n";
  for (const WorkspaceSlice& s : r.slices) {
    const std::array<std::size_t, 5> n = group_counts(s);
    std::string shares;
    for (std::size_t g = 0; g < 5; ++g)
      if (n[g] > 0)
        shares += fmt::format("{}{} {:.0f} %", shares.empty() ? "" : ", ", kLimitGroups[g],
                              100.0 * static_cast<double>(n[g]) / static_cast<double>(s.boundary.size()));
    out += fmt::format("  {} at {} = {:+.3f} m: {:.4f} m^2; {}\n", plane_name(s.spec.plane), fixed_axis(s.spec.plane),
                       s.spec.offset, s.area, s.boundary.empty() ? "empty" : shares);
  }
  const Vector3d& pos = r.orientation.spec.position;
  out += fmt::format("orientation workspace at x {:g}, y {:g}, z {:g} m: largest tilt over {} directions\n", pos.x(),
                     pos.y(), pos.z(), r.orientation.spec.directions);
  for (std::size_t t = 0; t < r.orientation.reach.size(); ++t) {
    const TiltExtremes e = tilt_extremes(r.orientation.reach[t]);
    if (e.reached == 0) {
      out += fmt::format("  yaw {:+g} deg: out of reach at zero tilt ({})\n", rad2deg(r.orientation.spec.torsions[t]),
                         describe(e.smallest_limit));
      continue;
    }
    out += fmt::format("  yaw {:+g} deg: {:.1f} to {:.1f} deg; least towards {:.0f} deg ({})\n",
                       rad2deg(r.orientation.spec.torsions[t]), rad2deg(e.smallest), rad2deg(e.largest),
                       rad2deg(e.smallest_azimuth), describe(e.smallest_limit));
  }
  const MapSummary ms = summarize_map(r.map);
  if (ms.inside > 0) {
    const Vector3d tw = map_node_position(r.map.grid, ms.max_twist_node);
    const Vector3d mg = map_node_position(r.map.grid, ms.margin_min_node);
    out += fmt::format(
        "map over x-y at z = {:+.3f} m ({} of {} nodes inside): largest |twist| {:.2f} deg (leg {} at x {:+.3f}, y "
        "{:+.3f} m), length error {:.3f} mm, condition {:.2f} to {:.2f}, smallest margin {:.3f} ({}, leg {} at x "
        "{:+.3f}, y {:+.3f} m)\n",
        r.map.grid.offset, ms.inside, r.map.points.size(), rad2deg(ms.max_twist), ms.max_twist_leg + 1, tw.x(), tw.y(),
        1e3 * ms.max_length_error, ms.condition_min, ms.condition_max, ms.margin_min,
        to_string(ms.margin_min_limit.status), ms.margin_min_limit.leg + 1, mg.x(), mg.y());
  } else {
    out += fmt::format("map over x-y at z = {:+.3f} m: no node inside the workspace\n", r.map.grid.offset);
  }
  return out;
}

int run_workspace(const WorkspaceCommandOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = load_config_from(o.model);
  const Model& model = config.rig.model();
  OutputFiles set("workspace");
  set.input("--config", o.model.config);
  set.folder("--out", o.out);
  const Results r = compute(model, o);
  if (!(r.volume.volume > 0.0))
    throw ExitError(kExitOutOfLimit, fmt::format("--orientation {}: no position is reachable there (every column of "
                                                 "the volume's grid is outside the limits); nothing was written",
                                                 printable(o.orientation)));

  const fs::path dir(o.out);
  std::vector<std::string> names;
  std::vector<Figure> figs;
  if (!o.no_csv) names.insert(names.end(), {"slices.csv", "orientation.csv", "map.csv"});
  if (!o.no_figures) {
    figs = figures(r, dir, model_source(o.model));
    for (const Figure& f : figs)
      for (const char* ext : {".png", ".svg"}) names.push_back(fs::path(f.stem).filename().string() + ext);
  }
  names.push_back("summary.json");
  if (!o.no_csv) {
    set.add((dir / "slices.csv").string(), slices_csv(r));
    set.add((dir / "orientation.csv").string(), orientation_csv(r));
    set.add((dir / "map.csv").string(), map_csv(r));
  }
  const std::string json = summary_json(model, o, r, names);
  set.add((dir / "summary.json").string(), json);
  set.stage();
  for (Figure& f : figs) f.stem = set.external(f.stem, {".png", ".svg"});
  if (!figs.empty()) write_figures(figs);
  set.commit();
  if (o.json) {
    set.finish(json);
    return kExitOk;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string text = text_report(model, o, r, defaults_note(config));
  text += fmt::format("\n{} written to {} in {:.1f} s\n", counted(set.paths().size(), "file"), o.out, wall);
  set.finish(text);
  return kExitOk;
}

}  // namespace

Command make_workspace_command(CLI::App& root) {
  auto o = std::make_shared<WorkspaceCommandOptions>();
  CLI::App* app = root.add_subcommand(
      "workspace",
      "The workspace and what bounds it (docs/theory/design.md §16): the constant-orientation workspace at "
      "--orientation (positions inside every limit: stroke of legs and commands, U-joint bend and singularity "
      "margin, platform singularity), its volume [m^3] to better than 1 % with the error stated, its boundary in "
      "x-y slices at --heights and the x-z and y-z slices with the limit that bounds each boundary point; the "
      "orientation workspace at --position (the largest tilt towards every direction, at each of --yaws); and maps "
      "over the x-y slice at --map-height (largest |twist| and length error and their leg, the Jacobian's "
      "condition, the margin to the nearest limit).\nWrites to --out: summary.json (SI), slices.csv, "
      "orientation.csv, map.csv (SI), and the figures slices_xy, slices_vertical, orientation, map_twist, "
      "map_dexterity (PNG and SVG; mm and deg where shown).");
  add_model_options(*app, o->model);
  app->add_option("--orientation", o->orientation, "roll,pitch,yaw of the constant-orientation workspace [deg]")
      ->capture_default_str();
  app->add_option("--heights", o->heights, "z of the x-y slices [m], comma-separated")->capture_default_str();
  app->add_option("--xz-at", o->xz_at, "y of the x-z slice [m]")->capture_default_str();
  app->add_option("--yz-at", o->yz_at, "x of the y-z slice [m]")->capture_default_str();
  app->add_option("--spacing", o->spacing, "between the slices' search lines [m]")->capture_default_str();
  app->add_option("--position", o->position, "x,y,z of the orientation workspace [m]")->capture_default_str();
  app->add_option("--yaws", o->yaws, "yaws (torsions) of the orientation workspace [deg], comma-separated")
      ->capture_default_str();
  app->add_option("--map-height", o->map_height, "z of the maps' x-y slice [m]")->capture_default_str();
  app->add_option("--map-spacing", o->map_spacing, "between the maps' nodes [m]")->capture_default_str();
  add_cell_option(*app, o->cell);
  app->add_option("--out", o->out, "Output folder (created if missing), written as a set: all files or none (exit 4)")
      ->capture_default_str();
  app->add_flag("--json", o->json, "Print summary.json instead of the text report");
  app->add_flag("--no-figures", o->no_figures, "Skip the figures (gnuplot)");
  app->add_flag("--no-csv", o->no_csv, "Skip the CSVs");
  add_scheduler_option(*app, o->scheduler);
  return {app, [o] { return run_workspace(*o); }};
}

}  // namespace hexatwist::cli
