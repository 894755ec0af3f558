// SPDX-License-Identifier: BSD-3-Clause
// Internal: Ds-optimal exact designs by exchange (docs/theory/calibration.md §13, "Where to
// measure"). Candidate k contributes the block J_k (r rows, p columns) to the information
// M = F + sum_{k in design} J_k^T J_k; the last n columns are nuisance parameters, and the criterion
// is the log determinant of the Schur complement of their block, log det M - log det M_nn. Adding
// a candidate changes M by rank r and exchanging one for another by rank 2r: the matrix determinant
// lemma gives the criterion's change from r x r quadratic forms, which the Woodbury identity keeps
// up to date, so that a sweep over every (station, candidate) pair costs O(r^2 p) per pair.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <vector>

namespace hexatwist::detail {

/// log det M - log det M_nn (M_nn the trailing `nuisance` x `nuisance` block) by Cholesky
/// factorisations; -infinity if M is not positive definite.
double ds_criterion(const Eigen::MatrixXd& M, int nuisance);

/// An exact design (each candidate at most once) and the Ds criterion's changes.
class DsDesign {
 public:
  /// `rows`: candidate k's block in rows r k .. r k + r - 1 (p columns); the last `nuisance`
  /// columns are the nuisance parameters; `fixed`: F (p x p, symmetric positive definite: the
  /// information every design has, so that M stays invertible when a station leaves). Throws
  /// hexatwist::Error for inconsistent sizes or an F that is not positive definite.
  DsDesign(Eigen::MatrixXd rows, int r, int nuisance, Eigen::MatrixXd fixed);

  int candidates() const noexcept { return static_cast<int>(rows_.rows() / r_); }
  /// The design: candidate indices by position.
  const std::vector<int>& design() const noexcept { return design_; }
  bool in_design(int k) const noexcept { return used_[static_cast<std::size_t>(k)] != 0; }
  /// M of the current design.
  const Eigen::MatrixXd& information() const noexcept { return M_; }
  /// Its criterion, log det M - log det M_nn (ds_criterion).
  double criterion() const noexcept { return criterion_; }

  /// The criterion's change on adding candidate k (rank r).
  double add_gain(int k) const;
  /// The criterion's change on replacing the design's station at `position` by candidate k (rank 2r).
  double swap_gain(int position, int k) const;
  /// The swap gains of every candidate for `position` (-infinity for those in the design).
  std::vector<double> swap_gains(int position) const;

  /// Adds candidate k (not in the design).
  void add(int k);
  /// Replaces the station at `position` by candidate k (not in the design).
  void swap(int position, int k);

  /// Adds, one at a time, the candidate of the largest gain until the design holds `count`.
  void greedy(int count);

  /// What exchange did.
  struct Exchanges {
    int sweeps = 0;          ///< sweeps over the design's positions
    int exchanges = 0;       ///< stations exchanged
    bool converged = false;  ///< the last sweep found no exchange gaining more than the tolerance
  };
  /// The modified Fedorov exchange (Cook & Nachtsheim 1980): each position in turn exchanged for
  /// the candidate of the largest gain if that gain exceeds `tolerance`; sweeps until one makes no
  /// exchange, at most `max_sweeps`.
  Exchanges exchange(int max_sweeps, double tolerance);

 private:
  struct Forms {
    Eigen::MatrixXd inverse;  // M^-1 (or M_nn^-1)
    Eigen::MatrixXd quad;     // A_k = J_k M^-1 J_k^T of every candidate, in rows r k ..
  };
  // Candidate k's block of all columns or of the nuisance ones.
  auto block(int k) const { return rows_.middleRows(static_cast<Eigen::Index>(r_) * k, r_); }
  double gain(const Forms& f, const Eigen::MatrixXd& rows, int position, int k) const;
  void swap_gains_of(const Forms& f, const Eigen::MatrixXd& rows, int position, std::vector<double>& out,
                     double sign) const;
  void refresh();
  // M += sum of U^T S U for the blocks `added` (+1) and `removed` (-1), the forms by Woodbury.
  void update(int added, int removed);
  static void woodbury(Forms& f, const Eigen::MatrixXd& rows, int r, int added, int removed);

  Eigen::MatrixXd rows_, nuisance_rows_, fixed_, M_;
  int r_ = 3, nuisance_ = 0;
  std::vector<int> design_;
  std::vector<char> used_;
  Forms all_, nuis_;
  double criterion_ = -std::numeric_limits<double>::infinity();
};

}  // namespace hexatwist::detail
