// SPDX-License-Identifier: BSD-3-Clause
#include "study_figures.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>

namespace hexatwist::cli {

namespace fs = std::filesystem;

double displacement(const ReportedTest& t, double time, const Vector6d& desired) {
  if (t.coordinate < 0) return time;
  const double v = desired[t.coordinate];
  return t.coordinate < 3 ? v : rad2deg(v);
}

std::string displacement_label(const ReportedTest& t) {
  if (t.coordinate < 0) return "time [s]";
  if (t.coordinate < 3) return fmt::format("commanded {} displacement [m]", kCoordinateNames[t.coordinate]);
  return fmt::format("commanded {} angle [deg]", kCoordinateNames[t.coordinate]);
}

namespace {

double displacement(const ReportedTest& t, const SimulationSample& s) { return displacement(t, s.time, s.desired); }

// The experiment beside the simulation: the error against the swept coordinate (or time), and its
// components in the base frame against time.
Figure measured_figure(const fs::path& dir, const ReportedTest& t) {
  const ReportedMeasurement& r = *t.measured;
  const Measurement& m = r.measurement;
  const char* strategy = to_string(r.strategy).data();
  Series measured{fmt::format("measured ({})", strategy), {}, {}, Series::Style::Solid};
  Series simulated{fmt::format("simulated ({}, closed loop)", strategy), {}, {}, Series::Style::Dashed};
  std::array<Series, 3> axes;
  for (int a = 0; a < 3; ++a)
    axes[static_cast<std::size_t>(a)].label = fmt::format("{} (base frame)", kCoordinateNames[a]);
  for (std::size_t k = m.window; k < m.points.size(); ++k) {
    const MeasuredPoint& p = m.points[k];
    const double x = displacement(t, p.time, p.desired);
    measured.x.push_back(x);
    measured.y.push_back(1e3 * p.error_B.norm());
    simulated.x.push_back(x);
    simulated.y.push_back(1e3 * r.simulated[k - m.window]);
    for (int a = 0; a < 3; ++a) {
      axes[static_cast<std::size_t>(a)].x.push_back(p.time);
      axes[static_cast<std::size_t>(a)].y.push_back(1e3 * p.error_B[a]);
    }
  }
  Figure f{(dir / (t.name + "_measured")).string(), "", {}};
  f.panels.push_back({fmt::format("{} ({}): measured and simulated error of point A", t.name, t.description),
                      displacement_label(t),
                      "position error [mm]",
                      {std::move(measured), std::move(simulated)}});
  f.panels.push_back({fmt::format("Measured error by axis, registered on {} points (rms residual {:.4f} mm)",
                                  m.registration.count, 1e3 * m.registration.rms_residual),
                      "time [s]",
                      "error [mm]",
                      {axes.begin(), axes.end()}});
  return f;
}

}  // namespace

std::vector<Figure> figures_of(const fs::path& dir, const ReportedTest& t, const Model& model) {
  // x: the swept coordinate (or time) by default; time for the transients of the servo.
  const auto series = [&](const std::string& label, const std::vector<SimulationSample>& samples, auto value,
                          Series::Style style = Series::Style::Solid, bool against_time = false) {
    Series s{label, {}, {}, style};
    s.x.reserve(samples.size());
    s.y.reserve(samples.size());
    for (std::size_t k = 0; k < samples.size(); ++k) {
      s.x.push_back(against_time ? samples[k].time : displacement(t, samples[k]));
      s.y.push_back(value(k, samples[k]));
    }
    return s;
  };
  const auto tracking = [&](double scale) {
    return [&t, scale](std::size_t k, const SimulationSample&) {
      return k < t.run.tracking_only.size() ? scale * t.run.tracking_only[k] : NAN;
    };
  };
  const auto& conv = t.run.conventional.samples;
  const auto& comp = t.run.compensated.samples;
  Figure error{(dir / (t.name + "_error")).string(), "", {}};
  Panel p{fmt::format("{} ({}): observation-point error", t.name, t.description),
          displacement_label(t),
          "position error [mm]",
          {}};
  p.series.push_back(
      series("conventional, closed loop", conv, [](std::size_t, const SimulationSample& s) { return 1e3 * s.error; }));
  p.series.push_back(series(
      "conventional, perfect servo", conv,
      [](std::size_t, const SimulationSample& s) { return 1e3 * s.error_twist_only; }, Series::Style::Dashed));
  p.series.push_back(
      series("compensated, closed loop", comp, [](std::size_t, const SimulationSample& s) { return 1e3 * s.error; }));
  error.panels.push_back(std::move(p));
  // On the scale of the twist error the compensated strategy is a flat line: zoom in on it,
  // against time, where the servo's transients (starts, stops, reversals) are apart.
  Panel zoom{fmt::format("Compensated, zoomed: the servo's own error (with perfect servos it is {:.1e} µm)",
                         1e6 * t.run.compensated.twist_only.max),
             "time [s]",
             "position error [µm]",
             {}};
  zoom.series.push_back(series(
      "compensated, closed loop", comp, [](std::size_t, const SimulationSample& s) { return 1e6 * s.error; },
      Series::Style::Solid, true));
  zoom.series.push_back(series("servo alone (no twist)", comp, tracking(1e6), Series::Style::Dashed, true));
  error.panels.push_back(std::move(zoom));

  // Legs that move alike (symmetry) would hide each other: say so in the legend.
  std::array<int, kLegs> same{};
  for (int i = 0; i < kLegs; ++i) {
    same[static_cast<std::size_t>(i)] = -1;
    for (int j = 0; j < i && same[static_cast<std::size_t>(i)] < 0; ++j) {
      double d = 0.0;
      for (const SimulationSample& s : conv) d = std::max(d, std::abs(s.twist[i] - s.twist[j]));
      if (d < 1e-6) same[static_cast<std::size_t>(i)] = j;
    }
  }
  const auto leg_label = [&](int i) {
    const int j = same[static_cast<std::size_t>(i)];
    return j < 0 ? fmt::format("leg {}", i + 1) : fmt::format("leg {} (= leg {})", i + 1, j + 1);
  };
  Figure legs{(dir / (t.name + "_legs")).string(), "", {}};
  Panel twist{fmt::format("{} ({}): twist of each leg (conventional run)", t.name, t.description),
              displacement_label(t),
              "twist [deg]",
              {}};
  Panel length{
      "Length error of each leg, real minus motor-side (Eq. 10)", displacement_label(t), "length error [mm]", {}};
  for (int i = 0; i < kLegs; ++i) {
    twist.series.push_back(
        series(leg_label(i), conv, [i](std::size_t, const SimulationSample& s) { return rad2deg(s.twist[i]); }));
    const double g = model.geometry().twist_gain[i];
    length.series.push_back(
        series(leg_label(i), conv, [i, g](std::size_t, const SimulationSample& s) { return 1e3 * g * s.twist[i]; }));
  }
  legs.panels.push_back(std::move(twist));
  legs.panels.push_back(std::move(length));
  std::vector<Figure> out{std::move(error), std::move(legs)};
  if (t.measured) out.push_back(measured_figure(dir, t));
  return out;
}

}  // namespace hexatwist::cli
