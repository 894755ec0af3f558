// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/design/axis_design.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "design/parallel.hpp"
#include "design/sampling.hpp"
#include "hexatwist/design/tolerance.hpp"
#include "hexatwist/error.hpp"
#include "hexatwist/kinematics/forward.hpp"
#include "kinematics/geometry.hpp"

namespace hexatwist {

Vector3d turned_axis(const Vector3d& axis, double turn, double tilt) noexcept {
  Vector3d v = axis;
  if (tilt != 0.0) {
    // Rotation about n = unit(axis x z), which lifts a horizontal axis towards +z.
    Vector3d n = axis.cross(Vector3d::UnitZ());
    if (n.norm() > 1e-12 * axis.norm()) {
      n.normalize();
      v = std::cos(tilt) * axis + std::sin(tilt) * n.cross(axis);
    }
  }
  return Eigen::AngleAxisd(turn, Vector3d::UnitZ()) * v;
}

ModelSpec turned_axes(const ModelSpec& spec, const AxisTurns& t) {
  ModelSpec out = spec;
  for (std::size_t i = 0; i < static_cast<std::size_t>(kLegs); ++i) {
    LegSpec& leg = out.legs[i];
    if (leg.axis_base_B != Vector3d::Zero()) leg.axis_base_B = turned_axis(leg.axis_base_B, t.base[i], t.base_tilt[i]);
    if (leg.axis_platform_P != Vector3d::Zero())
      leg.axis_platform_P = turned_axis(leg.axis_platform_P, t.platform[i], t.platform_tilt[i]);
  }
  return out;
}

namespace {

// ---------------------------------------------------------------------------------------------
// Evaluation with the library's own functions (the report, and the verification of a design).

// Share of each limit's range left at a pose, as nearest_limit measures it, into `margins`.
void update_margins(const Model& model, const CommandReport& r, double condition, std::size_t pose,
                    std::array<LimitMargin, kMarginKinds>& margins) {
  const LimitSpec& lim = model.spec().limits;
  const auto consider = [&](MarginKind kind, double share, Status s, int leg, double value, double bound) {
    LimitMargin& m = margins[static_cast<std::size_t>(kind)];
    if (share < m.share) m = LimitMargin{share, LimitReport{s, leg, value, bound}, pose};
  };
  const double half = 0.5 * (lim.length_max - lim.length_min);
  const Vector6d travel = r.legs.length - model.geometry().length_offset - r.length_error;
  Vector6d bend_base, bend_platform;
  bend_angles(model, r.legs, bend_base, bend_platform);
  for (int i = 0; i < kLegs; ++i) {
    const double l = r.legs.length[i], c = travel[i];
    consider(MarginKind::Stroke, (l - lim.length_min) / half, Status::StrokeBelowMin, i, l, lim.length_min);
    consider(MarginKind::Stroke, (lim.length_max - l) / half, Status::StrokeAboveMax, i, l, lim.length_max);
    consider(MarginKind::Command, (c - lim.length_min) / half, Status::StrokeBelowMin, i, c, lim.length_min);
    consider(MarginKind::Command, (lim.length_max - c) / half, Status::StrokeAboveMax, i, c, lim.length_max);
    consider(MarginKind::Bend, 1.0 - bend_base[i] / lim.bend_max, Status::BendBase, i, bend_base[i], lim.bend_max);
    consider(MarginKind::Bend, 1.0 - bend_platform[i] / lim.bend_max, Status::BendPlatform, i, bend_platform[i],
             lim.bend_max);
    if (model.geometry().has_axes[i] == 0.0) continue;
    const Vector3d s = r.legs.s_B.row(i).transpose();
    const double free_range = kPi / 2 - lim.singularity_margin;
    const double a = detail::line_axis_angle(s, model.leg(i).axis_base_B);
    const double d = detail::line_axis_angle(s, r.legs.axis_platform_B.row(i).transpose());
    consider(MarginKind::Singularity, (a - lim.singularity_margin) / free_range, Status::SingularBase, i, a,
             lim.singularity_margin);
    consider(MarginKind::Singularity, (d - lim.singularity_margin) / free_range, Status::SingularPlatform, i, d,
             lim.singularity_margin);
  }
  consider(MarginKind::Condition, 1.0 - std::log(std::max(condition, 1.0)) / std::log(lim.jacobian_condition_max),
           Status::PlatformSingularity, -1, condition, lim.jacobian_condition_max);
}

// |dA/d(relative lead error)| at a pose: the compensated command is short of the real twist term by
// eps * twist_gain * twist on every leg, which moves the platform by J_m^-1 of it (docs §17).
double lead_sensitivity(const Model& model, const CommandReport& r) {
  Matrix6d J;
  if (length_jacobian(model, r.legs, LengthKind::Motor, J) != Status::Ok) return NAN;
  const Vector6d rhs = model.geometry().twist_gain.cwiseProduct(r.twist);
  const Vector6d dx = J.partialPivLu().solve(rhs);
  const Vector3d arm = r.legs.R_BP * (model.spec().observation_P - model.spec().pivot_P);
  return (dx.head<3>() + dx.tail<3>().cross(arm)).norm();
}

// ---------------------------------------------------------------------------------------------
// The search: every leg's twist over the poses as a bilinear form of its two axes (docs §17),
// x = ja^T X jd_P and y = ja^T Y jd_P with X = (I - s s^T) R and Y = -[s]x R per pose, so that a
// candidate costs two 3x3 forms per pose.

using Params = std::array<double, 4>;  // turn of ja, turn of jd, tilt of ja, tilt of jd [rad]

// With tilts, the global grid samples each tilt at this many levels over [-max_tilt, max_tilt].
constexpr int kTiltLevels = 5;

struct Group {
  std::vector<int> legs;
  std::vector<double> sign;  // the in-plane turns' sign per leg (mirror legs turn the other way)
};

std::vector<Group> groups_of(AxisSymmetry s) {
  std::vector<Group> g;
  switch (s) {
    case AxisSymmetry::Symmetric:
      g.push_back({{0, 1, 2, 3, 4, 5}, {1, -1, 1, -1, 1, -1}});
      break;
    case AxisSymmetry::Threefold:
      g.push_back({{0, 2, 4}, {1, 1, 1}});
      g.push_back({{1, 3, 5}, {1, 1, 1}});
      break;
    case AxisSymmetry::PerLeg:
      for (int i = 0; i < kLegs; ++i) g.push_back({{i}, {1}});
      break;
  }
  return g;
}

struct LegData {
  std::array<Eigen::ArrayXd, 9> X, Y;  // row-major (k, l) -> 3k + l
  std::array<Eigen::ArrayXd, 3> s, q;  // s [B] and R^T s [P]
  Eigen::ArrayXd length;
  Matrix3d X0, Y0;                        // at home
  std::vector<Eigen::Index> near_stroke;  // poses whose command may leave the stroke through the twist
  Vector3d ja, jd;                        // the model's axes (unit)
  double gain = 0.0, offset = 0.0;
  bool has_axes = true;
};

struct SearchData {
  const Model& model;
  Eigen::Index required = 0, samples = 0;  // poses [0, required) then volume samples
  std::array<LegData, kLegs> legs;
  std::array<Eigen::ArrayXd, 18> W;  // lead objective: row r, leg i -> 6r + i of G_A J^-1 [m/m]
  double cos2_margin = 1.0;
  double lmin = 0.0, lmax = 0.0;
};

// Per-leg twist of candidate axes over every pose (x, y) and at home (x0, y0).
struct LegTwist {
  Eigen::ArrayXd x, y;
  double x0 = 1.0, y0 = 0.0;
};

LegTwist leg_twist(const LegData& d, const Vector3d& ja, const Vector3d& jd) {
  LegTwist t;
  const Eigen::Index n = d.length.size();
  t.x = Eigen::ArrayXd::Zero(n);
  t.y = Eigen::ArrayXd::Zero(n);
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) {
      const double c = ja[k] * jd[l];
      t.x += c * d.X[static_cast<std::size_t>(3 * k + l)];
      t.y += c * d.Y[static_cast<std::size_t>(3 * k + l)];
    }
  t.x0 = ja.dot(d.X0 * jd);
  t.y0 = ja.dot(d.Y0 * jd);
  return t;
}

// The candidate's verdict on one leg.
struct LegVerdict {
  bool feasible = true;  // every required pose keeps its margins and its command in the stroke
  double max_abs = 0.0;  // largest |twist| over the required poses [rad]
  Eigen::ArrayXd twist;  // signed twist over the required poses (lead objective only)
};

LegVerdict judge_leg(const SearchData& sd, const LegData& d, const Vector3d& ja, const Vector3d& jd, bool signed_twist,
                     std::vector<char>& lost) {
  LegVerdict v;
  const Eigen::Index nr = sd.required;
  const LegTwist t = leg_twist(d, ja, jd);
  const Eigen::ArrayXd sa = d.s[0] * ja[0] + d.s[1] * ja[1] + d.s[2] * ja[2];
  const Eigen::ArrayXd sq = d.q[0] * jd[0] + d.q[1] * jd[1] + d.q[2] * jd[2];
  const Eigen::ArrayXd r2 = t.x.square() + t.y.square();
  const double r02 = t.x0 * t.x0 + t.y0 * t.y0;
  const auto singular = [&](Eigen::Index p) {
    return sa[p] * sa[p] > sd.cos2_margin || sq[p] * sq[p] > sd.cos2_margin || !(r2[p] > 1e-24);
  };
  if (!(r02 > 1e-24)) {
    v.feasible = false;
    return v;
  }
  for (Eigen::Index p = 0; p < nr; ++p)
    if (singular(p)) {
      v.feasible = false;
      return v;
    }
  for (Eigen::Index p = nr; p < nr + sd.samples; ++p)
    if (singular(p)) lost[static_cast<std::size_t>(p - nr)] = 1;
  const auto delta = [&](Eigen::Index p) {
    return std::atan2(t.y[p] * t.x0 - t.x[p] * t.y0, t.x[p] * t.x0 + t.y[p] * t.y0);
  };
  for (const Eigen::Index p : d.near_stroke) {
    const double command = d.length[p] - d.offset - d.gain * delta(p);
    if (command >= sd.lmin && command <= sd.lmax) continue;
    if (p < nr) {
      v.feasible = false;
      return v;
    }
    lost[static_cast<std::size_t>(p - nr)] = 1;
  }
  // Largest |twist| over the required poses: the smallest cosine.
  const Eigen::ArrayXd cosine = (t.x.head(nr) * t.x0 + t.y.head(nr) * t.y0) / (r2.head(nr) * r02).sqrt();
  v.max_abs = nr > 0 ? std::acos(std::clamp(cosine.minCoeff(), -1.0, 1.0)) : 0.0;
  if (signed_twist) {
    v.twist.resize(nr);
    for (Eigen::Index p = 0; p < nr; ++p) v.twist[p] = delta(p);
  }
  return v;
}

// One candidate for one group of legs.
struct Score {
  bool feasible = false;
  double objective = INFINITY;
  std::size_t lost = 0;
  double change = 0.0;  // |params|: of equal designs, the one nearer the model's
};

bool better(const Score& a, const Score& b) {
  if (a.feasible != b.feasible) return a.feasible;
  if (a.objective != b.objective) return a.objective < b.objective;
  if (a.lost != b.lost) return a.lost < b.lost;
  return a.change < b.change;
}

class Search {
 public:
  Search(const SearchData& sd, const DesignOptions& o, std::vector<Group> groups)
      : sd_(sd), o_(o), groups_(std::move(groups)) {
    params_.assign(groups_.size(), Params{0, 0, 0, 0});
    best_.assign(groups_.size(), INFINITY);
    // The lead objective needs every leg's twist: the model's own axes to start with.
    std::vector<char> lost(static_cast<std::size_t>(sd.samples), 0);
    for (int i = 0; i < kLegs; ++i) {
      const LegData& d = sd.legs[static_cast<std::size_t>(i)];
      Eigen::ArrayXd& t = twist_[static_cast<std::size_t>(i)];
      if (o.objective == DesignObjective::LeadSensitivity && d.has_axes)
        t = judge_leg(sd, d, d.ja, d.jd, true, lost).twist;
      if (t.size() != sd.required) t = Eigen::ArrayXd::Zero(sd.required);  // no axes, or refused by a clearance
    }
  }

  std::size_t evaluations() const noexcept { return evaluations_; }
  const std::vector<Params>& params() const noexcept { return params_; }
  /// Each group's best objective found (infinite: no feasible axes).
  const std::vector<double>& best() const noexcept { return best_; }
  const std::vector<Group>& groups() const noexcept { return groups_; }

  // Axes of leg i of group g for the group's parameters.
  std::pair<Vector3d, Vector3d> axes(const Group& g, std::size_t k, const Params& p) const {
    const LegData& d = sd_.legs[static_cast<std::size_t>(g.legs[k])];
    return {turned_axis(d.ja, g.sign[k] * p[0], p[2]), turned_axis(d.jd, g.sign[k] * p[1], p[3])};
  }

  // The group's score for parameters p (other groups as they are).
  Score score(std::size_t gi, const Params& p, std::size_t budget, std::vector<Eigen::ArrayXd>* twists = nullptr) {
    ++evaluations_;
    const Group& g = groups_[gi];
    const bool lead = o_.objective == DesignObjective::LeadSensitivity;
    std::vector<char> lost(static_cast<std::size_t>(sd_.samples), 0);
    Score s;
    s.change = std::abs(p[0]) + std::abs(p[1]) + std::abs(p[2]) + std::abs(p[3]);
    double worst = 0.0;
    std::vector<Eigen::ArrayXd> local;
    for (std::size_t k = 0; k < g.legs.size(); ++k) {
      const LegData& d = sd_.legs[static_cast<std::size_t>(g.legs[k])];
      if (!d.has_axes) {
        local.emplace_back(Eigen::ArrayXd::Zero(sd_.required));
        continue;
      }
      const auto [ja, jd] = axes(g, k, p);
      LegVerdict v = judge_leg(sd_, d, ja, jd, lead, lost);
      if (!v.feasible) return s;
      const double weight = o_.objective == DesignObjective::LengthError ? std::abs(d.gain) : 1.0;
      worst = std::max(worst, weight * v.max_abs);
      local.push_back(std::move(v.twist));
    }
    s.lost = static_cast<std::size_t>(std::count(lost.begin(), lost.end(), 1));
    if (s.lost > budget) return s;
    s.feasible = true;
    s.objective = lead ? lead_objective(g, local) : worst;
    if (twists) *twists = std::move(local);
    return s;
  }

  // Global grid of in-plane turns (with tilts if asked: kTiltLevels of each over [-max_tilt,
  // max_tilt]), then a local compass search from the best few, for group gi; keeps the best in
  // params_. The largest twist is a maximum over poses, not smooth: a compass search stops at its
  // kinks, so the tilts are sampled globally as the turns are, not only searched from zero.
  void optimise_group(std::size_t gi, std::size_t budget) {
    const int n = std::max(1, static_cast<int>(std::lround(kPi / o_.grid_step)));
    struct Candidate {
      Score score;
      Params p;
    };
    std::vector<Candidate> grid;
    const Params current = params_[gi];
    std::vector<double> tilts{current[2]};
    if (o_.tilt && o_.max_tilt > 0.0) {
      tilts.clear();
      for (int k = 0; k < kTiltLevels; ++k) tilts.push_back(o_.max_tilt * (2.0 * k / (kTiltLevels - 1) - 1.0));
    }
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        for (const double ta : tilts)
          for (const double td : o_.tilt&& o_.max_tilt > 0.0 ? tilts : std::vector<double>{current[3]}) {
            // Turns in [-90, 90) deg: an axis is a line, so this covers every direction in the plane.
            const Params p{-kPi / 2 + kPi * a / n, -kPi / 2 + kPi * b / n, ta, td};
            grid.push_back({score(gi, p, budget), p});
          }
    grid.push_back({score(gi, current, budget), current});
    std::sort(grid.begin(), grid.end(),
              [](const Candidate& x, const Candidate& y) { return better(x.score, y.score); });
    Candidate best = grid.front();
    const std::size_t starts = std::min<std::size_t>(4, grid.size());
    for (std::size_t k = 0; k < starts; ++k) {
      if (!grid[k].score.feasible) break;
      Candidate c = grid[k];
      for (double step = 0.5 * o_.grid_step; step >= o_.fine_step; step *= 0.5) {
        for (bool moved = true; moved;) {
          moved = false;
          for (int dim = 0; dim < (o_.tilt ? 4 : 2); ++dim)
            for (const double sign : {1.0, -1.0}) {
              Params p = c.p;
              p[static_cast<std::size_t>(dim)] += sign * step;
              if (dim >= 2 && std::abs(p[static_cast<std::size_t>(dim)]) > o_.max_tilt) continue;
              const Score s = score(gi, p, budget);
              if (better(s, c.score)) {
                c = {s, p};
                moved = true;
              }
            }
        }
      }
      if (better(c.score, best.score)) best = c;
    }
    params_[gi] = best.p;
    best_[gi] = best.score.feasible ? best.score.objective : INFINITY;
    if (o_.objective == DesignObjective::LeadSensitivity) {
      std::vector<Eigen::ArrayXd> twists;
      (void)score(gi, best.p, budget, &twists);
      for (std::size_t k = 0; k < groups_[gi].legs.size(); ++k)
        twist_[static_cast<std::size_t>(groups_[gi].legs[k])] = twists[k];
    }
  }

  // The turns of every leg.
  AxisTurns turns() const {
    AxisTurns t;
    for (std::size_t gi = 0; gi < groups_.size(); ++gi) {
      const Group& g = groups_[gi];
      for (std::size_t k = 0; k < g.legs.size(); ++k) {
        const auto i = static_cast<std::size_t>(g.legs[k]);
        t.base[i] = g.sign[k] * params_[gi][0];
        t.platform[i] = g.sign[k] * params_[gi][1];
        t.base_tilt[i] = params_[gi][2];
        t.platform_tilt[i] = params_[gi][3];
      }
    }
    return t;
  }

 private:
  // Largest |G_A J^-1 diag(k) twist| over the required poses with group g's legs at `local`.
  double lead_objective(const Group& g, const std::vector<Eigen::ArrayXd>& local) const {
    std::array<const Eigen::ArrayXd*, kLegs> tw;
    for (int i = 0; i < kLegs; ++i) tw[static_cast<std::size_t>(i)] = &twist_[static_cast<std::size_t>(i)];
    for (std::size_t k = 0; k < g.legs.size(); ++k) tw[static_cast<std::size_t>(g.legs[k])] = &local[k];
    Eigen::ArrayXd norm2 = Eigen::ArrayXd::Zero(sd_.required);
    for (int r = 0; r < 3; ++r) {
      Eigen::ArrayXd row = Eigen::ArrayXd::Zero(sd_.required);
      for (int i = 0; i < kLegs; ++i)
        row += sd_.W[static_cast<std::size_t>(6 * r + i)] * sd_.legs[static_cast<std::size_t>(i)].gain *
               *tw[static_cast<std::size_t>(i)];
      norm2 += row.square();
    }
    return sd_.required > 0 ? std::sqrt(norm2.maxCoeff()) : 0.0;
  }

  const SearchData& sd_;
  const DesignOptions& o_;
  std::vector<Group> groups_;
  std::vector<Params> params_;
  std::vector<double> best_;
  std::array<Eigen::ArrayXd, kLegs> twist_;  // current signed twists (lead objective)
  std::size_t evaluations_ = 0;
};

// The per-pose data of every leg for the poses (required first, then the volume samples).
std::unique_ptr<SearchData> search_data(const Model& model, const std::vector<Pose>& required,
                                        const std::vector<Pose>& samples, const DesignOptions& o) {
  auto sd = std::make_unique<SearchData>(SearchData{model, 0, 0, {}, {}, 1.0, 0.0, 0.0});
  sd->required = static_cast<Eigen::Index>(required.size());
  sd->samples = static_cast<Eigen::Index>(samples.size());
  const Eigen::Index n = sd->required + sd->samples;
  const LimitSpec& lim = model.spec().limits;
  sd->cos2_margin =
      o.clearance > 0.0 ? std::pow(std::cos(lim.singularity_margin + o.clearance), 2) : model.cos2_singularity_margin();
  sd->lmin = model.length_min_accepted();
  sd->lmax = model.length_max_accepted();
  for (int i = 0; i < kLegs; ++i) {
    LegData& d = sd->legs[static_cast<std::size_t>(i)];
    for (auto& a : d.X) a.resize(n);
    for (auto& a : d.Y) a.resize(n);
    for (auto& a : d.s) a.resize(n);
    for (auto& a : d.q) a.resize(n);
    d.length.resize(n);
    const Leg& leg = model.leg(i);
    d.has_axes = model.geometry().has_axes[i] != 0.0;
    d.ja = d.has_axes ? leg.axis_base_B : Vector3d::UnitX();
    d.jd = d.has_axes ? leg.axis_platform_P : Vector3d::UnitX();
    d.gain = leg.twist_gain;
    d.offset = leg.length_offset;
  }
  for (auto& a : sd->W) a.resize(sd->required);
  const auto fill = [&](const LegState& st, int i, Matrix3d& X, Matrix3d& Y) {
    const Vector3d s = st.s_B.row(i).transpose();
    X = (Matrix3d::Identity() - s * s.transpose()) * st.R_BP;
    Matrix3d S;
    S << 0, -s.z(), s.y(), s.z(), 0, -s.x(), -s.y(), s.x(), 0;
    Y = -S * st.R_BP;
  };
  LegState st;
  if (inverse_kinematics(model, Pose{}, st) != Status::Ok) throw Error("design: home has no inverse kinematics");
  for (int i = 0; i < kLegs; ++i) {
    LegData& d = sd->legs[static_cast<std::size_t>(i)];
    fill(st, i, d.X0, d.Y0);
  }
  const double reach = lim.length_max - lim.length_min;
  for (Eigen::Index p = 0; p < n; ++p) {
    const Pose& pose =
        p < sd->required ? required[static_cast<std::size_t>(p)] : samples[static_cast<std::size_t>(p - sd->required)];
    if (inverse_kinematics(model, pose, st) != Status::Ok) throw Error("design: a pose has no inverse kinematics");
    for (int i = 0; i < kLegs; ++i) {
      LegData& d = sd->legs[static_cast<std::size_t>(i)];
      Matrix3d X, Y;
      fill(st, i, X, Y);
      for (int k = 0; k < 9; ++k) {
        d.X[static_cast<std::size_t>(k)][p] = X(k / 3, k % 3);
        d.Y[static_cast<std::size_t>(k)][p] = Y(k / 3, k % 3);
      }
      const Vector3d s = st.s_B.row(i).transpose();
      const Vector3d q = st.R_BP.transpose() * s;
      for (int k = 0; k < 3; ++k)
        d.s[static_cast<std::size_t>(k)][p] = s[k], d.q[static_cast<std::size_t>(k)][p] = q[k];
      d.length[p] = st.length[i];
      // The twist moves the command by at most |k| pi: only these poses can leave the stroke by it.
      const double c = st.length[i] - d.offset, swing = std::abs(d.gain) * kPi;
      if (c - swing < sd->lmin || c + swing > sd->lmax || !(reach > 0.0)) d.near_stroke.push_back(p);
    }
    if (p < sd->required && o.objective == DesignObjective::LeadSensitivity) {
      Matrix6d J;
      if (length_jacobian(model, st, LengthKind::Motor, J) != Status::Ok) throw Error("design: singular leg");
      const Vector3d arm = st.R_BP * (model.spec().observation_P - model.spec().pivot_P);
      Eigen::Matrix<double, 3, 6> G;
      G.leftCols<3>() = Matrix3d::Identity();
      Matrix3d A;
      A << 0, -arm.z(), arm.y(), arm.z(), 0, -arm.x(), -arm.y(), arm.x(), 0;
      G.rightCols<3>() = -A;  // dw x arm = -[arm]x dw
      const Eigen::Matrix<double, 3, 6> W = G * J.inverse();
      for (int r = 0; r < 3; ++r)
        for (int i = 0; i < kLegs; ++i) sd->W[static_cast<std::size_t>(6 * r + i)][p] = W(r, i);
    }
  }
  return sd;
}

// Positions of the workspace at volume_rpy: drawn in its box, kept where the model reaches them.
std::vector<Pose> volume_samples(const Model& model, const DesignOptions& o) {
  std::vector<Pose> out;
  Box box;
  if (workspace_bounds(model, o.volume_rpy, box) != Status::Ok) return out;
  Vector6d command;
  LimitReport report;
  for (int k = 0; k < o.volume_samples; ++k) {
    detail::SampleStream r(o.seed ^ 0x5eed5eedULL, static_cast<std::uint64_t>(k));
    Pose pose;
    for (int c = 0; c < 3; ++c) pose.position[c] = box.lower[c] + (box.upper[c] - box.lower[c]) * r.uniform();
    pose.rpy = o.volume_rpy;
    if (motor_commands(model, pose, Strategy::Compensated, command, report) == Status::Ok) out.push_back(pose);
  }
  return out;
}

double objective_of(const DesignEvaluation& e, DesignObjective o) {
  switch (o) {
    case DesignObjective::LengthError:
      return e.max_length_error;
    case DesignObjective::LeadSensitivity:
      return e.max_lead_sensitivity;
    case DesignObjective::Twist:
      break;
  }
  return e.max_twist;
}

}  // namespace

void check_design_options(const DesignOptions& o) {
  const auto refuse = [](const char* field, const std::string& expected, double got) {
    throw ParameterError(fmt::format("design: {}: expected {}, got {:g}", field, expected, got), field);
  };
  if (!(o.grid_step > 0.0 && o.grid_step <= kPi / 2)) refuse("grid_step", "0 < grid_step <= pi/2 rad", o.grid_step);
  if (!(o.fine_step > 0.0 && o.fine_step <= o.grid_step))
    refuse("fine_step", "0 < fine_step <= grid_step [rad]", o.fine_step);
  if (!(o.max_tilt >= 0.0 && o.max_tilt < kPi / 2)) refuse("max_tilt", "0 <= max_tilt < pi/2 rad", o.max_tilt);
  if (!(o.clearance >= 0.0 && o.clearance < kMaxClearance))
    refuse("clearance", fmt::format("0 <= clearance < {:g} rad (80 deg)", kMaxClearance), o.clearance);
  if (!(o.max_volume_loss >= 0.0 && o.max_volume_loss <= 1.0))
    refuse("max_volume_loss", "a fraction from 0 to 1", o.max_volume_loss);
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(o.volume_rpy[a])) refuse("volume_rpy", "finite roll, pitch, yaw [rad]", o.volume_rpy[a]);
  if (!(o.volume.cell >= 0.0 && o.volume.cell <= 1.0)) refuse("cell", "0 (automatic) to 1 m", o.volume.cell);
  if (!(o.volume_samples >= 0 && o.volume_samples <= kMaxVolumeSamples))
    refuse("volume_samples", fmt::format("0 to {}", kMaxVolumeSamples), o.volume_samples);
  if (o.threads < 0) refuse("threads", "0 (every core) or more", o.threads);
}

Status evaluate_design(const Model& model, const std::vector<Pose>& poses, const DesignOptions& options, bool volume,
                       DesignEvaluation& out) {
  check_design_options(options);
  out = DesignEvaluation{};
  out.poses = poses.size();
  out.first_refused = poses.size();
  struct PerPose {
    bool ok = false;
    LimitReport limit;
    Vector6d twist, length_error;
    double lead = 0.0;
    std::array<LimitMargin, kMarginKinds> margins{};
  };
  std::vector<PerPose> per(poses.size());
  detail::for_blocks(poses.size(), 256, options.threads, [&](std::size_t begin, std::size_t end) {
    auto report = std::make_unique<CommandReport>();
    for (std::size_t k = begin; k < end; ++k) {
      PerPose& r = per[k];
      Vector6d command;
      r.ok = motor_commands(model, poses[k], Strategy::Compensated, command, r.limit) == Status::Ok;
      if (!r.ok) continue;
      (void)compute_commands(model, poses[k], *report);
      double condition = NAN;
      (void)jacobian_condition(model, report->legs, condition);
      r.twist = report->twist;
      r.length_error = report->length_error;
      r.lead = lead_sensitivity(model, *report);
      update_margins(model, *report, condition, k, r.margins);
    }
  });
  for (std::size_t k = 0; k < per.size(); ++k) {
    const PerPose& r = per[k];
    if (!r.ok) {
      if (out.first_refused == poses.size()) {
        out.first_refused = k;
        out.refused = r.limit;
      }
      continue;
    }
    ++out.reached;
    Eigen::Index leg;
    const double t = r.twist.cwiseAbs().maxCoeff(&leg);
    if (t > out.max_twist) out.max_twist = t, out.twist_leg = static_cast<int>(leg), out.twist_pose = k;
    out.max_length_error = std::max(out.max_length_error, r.length_error.cwiseAbs().maxCoeff());
    out.max_lead_sensitivity = std::max(out.max_lead_sensitivity, r.lead);
    for (int m = 0; m < kMarginKinds; ++m) {
      const LimitMargin& x = r.margins[static_cast<std::size_t>(m)];
      if (x.share < out.margins[static_cast<std::size_t>(m)].share) out.margins[static_cast<std::size_t>(m)] = x;
    }
  }
  // With exact compensation the controller knows the nominal axes only: the real axes' errors are
  // what is left. The linearised point A error (tolerance_linear) for kDesignAxisSigma on both axes
  // of every leg, its 95th percentile over the reached poses.
  std::vector<Pose> reached;
  for (std::size_t k = 0; k < per.size(); ++k)
    if (per[k].ok) reached.push_back(poses[k]);
  ToleranceSigmas axes_only;
  axes_only.base_joint = axes_only.platform_joint = axes_only.lead = axes_only.offset = 0.0;
  axes_only.base_axis = axes_only.platform_axis = kDesignAxisSigma;
  ToleranceLinear linear;
  if (!reached.empty() && tolerance_linear(model, reached, axes_only, linear, options.threads) == Status::Ok) {
    ToleranceSummary summary;
    linear_quantiles(linear, summary, options.threads);
    out.axis_sensitivity = summary.point_linear.p95;
  }
  if (volume) {
    VolumeOptions vo = options.volume;
    vo.threads = options.threads;
    WorkspaceVolume v;
    if (const Status s = workspace_volume(model, options.volume_rpy, vo, v); s != Status::Ok) return s;
    out.volume = v.volume;
    out.volume_error = v.error;
  }
  return Status::Ok;
}

Status design_axes(const Model& model, const std::vector<Pose>& required_in, const DesignOptions& o, AxisDesign& out) {
  out = AxisDesign{};
  out.designed = model.spec();
  check_design_options(o);
  // The required poses the model reaches, and home (the Model checks it).
  std::vector<Pose> required{Pose{}};
  Vector6d command;
  LimitReport report;
  for (const Pose& p : required_in)
    if (motor_commands(model, p, Strategy::Compensated, command, report) == Status::Ok) required.push_back(p);
  if (const Status s = evaluate_design(model, required, o, true, out.before); s != Status::Ok) return s;
  out.after = out.before;
  out.objective_before = out.objective_after = objective_of(out.before, o.objective);
  if (!model.has_twist()) return Status::Ok;  // no twist: nothing to design

  const std::vector<Pose> samples = volume_samples(model, o);
  const std::unique_ptr<SearchData> sd = search_data(model, required, samples, o);
  // The twist of a leg depends on its own axes only: no axes do better than the worst leg's own best,
  // each leg searched alone with the volume left free (a relaxation of every symmetry and budget).
  const bool decoupled = o.objective != DesignObjective::LeadSensitivity;
  // Decoupled objectives: each group once. The lead objective couples the legs: sweeps over the groups.
  const std::size_t group_count = groups_of(o.symmetry).size();
  const int sweeps = !decoupled && group_count > 1 ? 3 : 1;
  const std::size_t steps =
      (decoupled ? static_cast<std::size_t>(kLegs) : 0) + group_count * static_cast<std::size_t>(sweeps);
  std::size_t step = 0;
  const auto told = [&] {
    if (o.progress) o.progress(++step, steps);
  };
  if (o.progress) o.progress(0, steps);
  if (decoupled) {
    Search alone(*sd, o, groups_of(AxisSymmetry::PerLeg));
    out.objective_bound = 0.0;
    for (std::size_t g = 0; g < alone.groups().size(); ++g) {
      alone.optimise_group(g, samples.size());
      out.objective_bound = std::max(out.objective_bound, alone.best()[g]);
      told();
    }
    out.evaluations += alone.evaluations();
  }
  const double volume_floor = (1.0 - o.max_volume_loss) * out.before.volume;
  // The samples a group may lose; halved after each design the verification refuses.
  double budget_fraction = o.max_volume_loss;
  for (int attempt = 1; attempt <= 4; ++attempt) {
    out.attempts = attempt;
    Search search(*sd, o, groups_of(o.symmetry));
    const std::size_t groups = search.groups().size();
    const auto budget =
        static_cast<std::size_t>(budget_fraction * static_cast<double>(samples.size()) / static_cast<double>(groups));
    for (int sweep = 0; sweep < sweeps; ++sweep)
      for (std::size_t g = 0; g < groups; ++g) {
        search.optimise_group(g, budget);
        if (attempt == 1) told();
      }
    out.evaluations += search.evaluations();

    const AxisTurns turns = search.turns();
    const ModelSpec spec = turned_axes(model.spec(), turns);
    std::optional<Model> designed;
    try {
      designed.emplace(spec);
    } catch (const Error&) {
      budget_fraction *= 0.5;  // cannot happen for a design that keeps home; kept as a guard
      continue;
    }
    DesignEvaluation after;
    if (const Status s = evaluate_design(*designed, required, o, true, after); s != Status::Ok) return s;
    if (after.reached == required.size() && after.volume >= volume_floor &&
        objective_of(after, o.objective) <= out.objective_before) {
      out.turns = turns;
      out.designed = spec;
      out.after = after;
      out.objective_after = objective_of(after, o.objective);
      return Status::Ok;
    }
    budget_fraction *= 0.5;
  }
  return Status::Ok;  // the model's own axes: no design kept every limit and the volume
}

}  // namespace hexatwist
