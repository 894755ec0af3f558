// SPDX-License-Identifier: BSD-3-Clause
#include "calibration/ds_design.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>

#include "hexatwist/error.hpp"

namespace hexatwist::detail {
namespace {

constexpr double kMinusInfinity = -std::numeric_limits<double>::infinity();
// Blocks of up to 4 targets' rows: the small matrices stay on the stack.
constexpr int kMaxRows = 12;
using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxRows, kMaxRows>;
using Wide = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 2 * kMaxRows, 2 * kMaxRows>;

// log det of a symmetric positive definite matrix; -infinity if it is not one.
template <class Matrix>
double log_det_spd(const Matrix& A) {
  const Eigen::LLT<Matrix> llt(A);
  if (llt.info() != Eigen::Success) return kMinusInfinity;
  const double d = 2.0 * llt.matrixLLT().diagonal().array().log().sum();
  return std::isfinite(d) ? d : kMinusInfinity;
}

// Every candidate's quadratic form A_k = J_k inverse J_k^T. The product is coefficient-based
// (lazyProduct): Eigen 3.4's blocked product packs its operands with aligned vector stores into
// buffers aligned to EIGEN_MAX_ALIGN_BYTES (16, CMakeLists.txt), which AVX's 32-byte stores may miss
// (UBSan: a misaligned store in gemm_pack_lhs).
void quadratic_forms(const Eigen::MatrixXd& inverse, const Eigen::MatrixXd& rows, int r, Eigen::MatrixXd& quad) {
  const Eigen::MatrixXd JM = rows.lazyProduct(inverse);
  quad.resize(rows.rows(), r);
  for (Eigen::Index k = 0; k < rows.rows(); k += r)
    quad.middleRows(k, r).noalias() = JM.middleRows(k, r) * rows.middleRows(k, r).transpose();
}

Eigen::MatrixXd spd_inverse(const Eigen::MatrixXd& M) {
  return M.llt().solve(Eigen::MatrixXd::Identity(M.rows(), M.cols()));
}

}  // namespace

double ds_criterion(const Eigen::MatrixXd& M, int nuisance) {
  const double full = log_det_spd(M);
  if (nuisance == 0 || !std::isfinite(full)) return full;
  const double nuis = log_det_spd(Eigen::MatrixXd(M.bottomRightCorner(nuisance, nuisance)));
  return std::isfinite(nuis) ? full - nuis : kMinusInfinity;
}

DsDesign::DsDesign(Eigen::MatrixXd rows, int r, int nuisance, Eigen::MatrixXd fixed)
    : rows_(std::move(rows)), fixed_(std::move(fixed)), r_(r), nuisance_(nuisance) {
  const Eigen::Index p = rows_.cols();
  if (r < 1 || r > kMaxRows || rows_.rows() % r != 0 || nuisance < 0 || nuisance > p || fixed_.rows() != p ||
      fixed_.cols() != p)
    throw Error(
        fmt::format("Ds design: {} rows of {} columns in blocks of {}, {} nuisance columns and a {}x{} fixed "
                    "information do not fit (blocks of 1 to {} rows)",
                    rows_.rows(), p, r, nuisance, fixed_.rows(), fixed_.cols(), kMaxRows));
  if (!std::isfinite(ds_criterion(fixed_, nuisance)))
    throw Error("Ds design: the fixed information is not positive definite");
  nuisance_rows_ = rows_.rightCols(nuisance);
  used_.assign(static_cast<std::size_t>(candidates()), 0);
  refresh();
}

void DsDesign::refresh() {
  M_ = fixed_;
  for (const int k : design_) M_.noalias() += block(k).transpose() * block(k);
  all_.inverse = spd_inverse(M_);
  quadratic_forms(all_.inverse, rows_, r_, all_.quad);
  if (nuisance_ > 0) {
    nuis_.inverse = spd_inverse(M_.bottomRightCorner(nuisance_, nuisance_));
    quadratic_forms(nuis_.inverse, nuisance_rows_, r_, nuis_.quad);
  }
  criterion_ = ds_criterion(M_, nuisance_);
}

// One part's log det change: adding k (position < 0) is det(I + A_k) by the determinant lemma;
// replacing the station at `position` (candidate i) by k is det(I - A_i) det(I + A_k + B Q B^T)
// with B = J_k M^-1 J_i^T and Q = (I - A_i)^-1 (the lemma for the removal, then for the addition
// with M - J_i^T J_i inverted by Woodbury).
double DsDesign::gain(const Forms& f, const Eigen::MatrixXd& rows, int position, int k) const {
  const auto R = static_cast<Eigen::Index>(r_);
  const Small I = Small::Identity(R, R);
  const Small A_k = f.quad.middleRows(R * k, R);
  if (position < 0) return log_det_spd(Small(I + A_k));
  const int i = design_[static_cast<std::size_t>(position)];
  const Small A_i = f.quad.middleRows(R * i, R);
  const Small removed = I - A_i;
  const Small B = rows.middleRows(R * k, R) * (f.inverse * rows.middleRows(R * i, R).transpose());
  const Small Q = removed.llt().solve(I);
  return log_det_spd(removed) + log_det_spd(Small(I + A_k + B * Q * B.transpose()));
}

double DsDesign::add_gain(int k) const {
  return gain(all_, rows_, -1, k) - (nuisance_ > 0 ? gain(nuis_, nuisance_rows_, -1, k) : 0.0);
}

double DsDesign::swap_gain(int position, int k) const {
  return gain(all_, rows_, position, k) - (nuisance_ > 0 ? gain(nuis_, nuisance_rows_, position, k) : 0.0);
}

// gain() for every candidate at once: B for all of them is one product of the rows with M^-1 J_i^T.
void DsDesign::swap_gains_of(const Forms& f, const Eigen::MatrixXd& rows, int position, std::vector<double>& out,
                             double sign) const {
  const auto R = static_cast<Eigen::Index>(r_);
  const int i = design_[static_cast<std::size_t>(position)];
  const Small I = Small::Identity(R, R);
  const Small removed = I - Small(f.quad.middleRows(R * i, R));
  const double base = log_det_spd(removed);
  const Small Q = removed.llt().solve(I);
  const Eigen::MatrixXd B = rows.lazyProduct(f.inverse * rows.middleRows(R * i, R).transpose());
  for (int k = 0; k < candidates(); ++k) {
    if (used_[static_cast<std::size_t>(k)] != 0) continue;
    const Small Bk = B.middleRows(R * k, R);
    out[static_cast<std::size_t>(k)] +=
        sign * (base + log_det_spd(Small(I + Small(f.quad.middleRows(R * k, R)) + Bk * Q * Bk.transpose())));
  }
}

std::vector<double> DsDesign::swap_gains(int position) const {
  std::vector<double> out(static_cast<std::size_t>(candidates()), 0.0);
  swap_gains_of(all_, rows_, position, out, 1.0);
  if (nuisance_ > 0) swap_gains_of(nuis_, nuisance_rows_, position, out, -1.0);
  for (std::size_t k = 0; k < out.size(); ++k)
    if (used_[k] != 0 || std::isnan(out[k])) out[k] = kMinusInfinity;
  return out;
}

// The forms after M += U^T S U (U the blocks of `added` and `removed`, S = diag(I, -I)):
// M'^-1 = M^-1 - W K^-1 W^T with W = M^-1 U^T, K = S + U W, so A'_k = A_k - C_k K^-1 C_k^T with
// C_k = J_k W.
void DsDesign::woodbury(Forms& f, const Eigen::MatrixXd& rows, int r, int added, int removed) {
  const auto R = static_cast<Eigen::Index>(r);
  const Eigen::Index m = (added >= 0 ? R : 0) + (removed >= 0 ? R : 0);
  Eigen::MatrixXd U(m, rows.cols());
  Wide S = Wide::Zero(m, m);
  Eigen::Index at = 0;
  for (const auto& [k, sign] : {std::pair{added, 1.0}, std::pair{removed, -1.0}}) {
    if (k < 0) continue;
    U.middleRows(at, R) = rows.middleRows(R * k, R);
    S.diagonal().segment(at, R).setConstant(sign);
    at += R;
  }
  const Eigen::MatrixXd W = f.inverse * U.transpose();
  const Wide K = S + U * W;
  const Wide K_inv = K.fullPivLu().inverse();
  const Eigen::MatrixXd C = rows.lazyProduct(W);
  for (Eigen::Index k = 0; k < rows.rows(); k += R) {
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxRows, 2 * kMaxRows> Ck = C.middleRows(k, R);
    f.quad.middleRows(k, R).noalias() -= Ck * K_inv * Ck.transpose();
  }
}

void DsDesign::update(int added, int removed) {
  if (added >= 0) M_.noalias() += block(added).transpose() * block(added);
  if (removed >= 0) M_.noalias() -= block(removed).transpose() * block(removed);
  woodbury(all_, rows_, r_, added, removed);
  // The inverses themselves afresh from M (p x p, cheap beside the forms of every candidate).
  all_.inverse = spd_inverse(M_);
  if (nuisance_ > 0) {
    woodbury(nuis_, nuisance_rows_, r_, added, removed);
    nuis_.inverse = spd_inverse(M_.bottomRightCorner(nuisance_, nuisance_));
  }
  criterion_ = ds_criterion(M_, nuisance_);
}

void DsDesign::add(int k) {
  if (k < 0 || k >= candidates() || in_design(k))
    throw Error(fmt::format("Ds design: candidate {} cannot be added", k));
  update(k, -1);
  design_.push_back(k);
  used_[static_cast<std::size_t>(k)] = 1;
}

void DsDesign::swap(int position, int k) {
  if (position < 0 || position >= static_cast<int>(design_.size()) || k < 0 || k >= candidates() || in_design(k))
    throw Error(fmt::format("Ds design: station {} cannot be exchanged for candidate {}", position, k));
  const int i = design_[static_cast<std::size_t>(position)];
  update(k, i);
  design_[static_cast<std::size_t>(position)] = k;
  used_[static_cast<std::size_t>(i)] = 0;
  used_[static_cast<std::size_t>(k)] = 1;
}

void DsDesign::greedy(int count) {
  if (count > candidates()) throw Error(fmt::format("Ds design: {} stations from {} candidates", count, candidates()));
  while (static_cast<int>(design_.size()) < count) {
    int best = -1;
    double best_gain = kMinusInfinity;
    for (int k = 0; k < candidates(); ++k) {
      if (in_design(k)) continue;
      const double g = add_gain(k);
      if (best < 0 || g > best_gain) best = k, best_gain = g;
    }
    add(best);
  }
}

DsDesign::Exchanges DsDesign::exchange(int max_sweeps, double tolerance) {
  Exchanges result;
  while (result.sweeps < max_sweeps && !result.converged) {
    refresh();  // the forms afresh once a sweep: no drift from the updates accumulates
    ++result.sweeps;
    result.converged = true;
    for (int position = 0; position < static_cast<int>(design_.size()); ++position) {
      const std::vector<double> gains = swap_gains(position);
      int best = -1;
      for (int k = 0; k < candidates(); ++k)
        if (gains[static_cast<std::size_t>(k)] > tolerance &&
            (best < 0 || gains[static_cast<std::size_t>(k)] > gains[static_cast<std::size_t>(best)]))
          best = k;
      if (best < 0) continue;
      swap(position, best);
      ++result.exchanges;
      result.converged = false;
    }
  }
  return result;
}

}  // namespace hexatwist::detail
