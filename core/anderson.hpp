#pragma once
/// \file anderson.hpp
/// \brief Anderson acceleration (Walker & Ni 2011, "type II", restarted) of a fixed
/// point x = F(x), shared by the contact-pairing loops of the FOM and ROM solvers.
#include <Eigen/Dense>
#include <vector>

namespace contactrom {

/// \brief Keeps the last `depth` differences of the iterates and their residuals
/// r = F(x) − x, and extrapolates x_next = F(x) − ΔF γ with γ = argmin |r − ΔR γ|
/// (normal equations, a pivoted LDLᵀ drops dependent differences). The history is
/// cleared whenever the residual grows.
class AndersonMixer {
 public:
  /// \param depth number of differences kept (0: plain fixed-point iteration)
  explicit AndersonMixer(int depth);

  /// \returns the next iterate, given the current one `x` and its image `f` = F(x).
  Eigen::VectorXd next(const Eigen::VectorXd& x, const Eigen::VectorXd& f);

  /// \brief Drops the differences but keeps the last point: the next call mixes
  /// with that point only (e.g. after an extrapolation the caller rejected).
  void restart() { m_df.clear(), m_dr.clear(); }
  /// \brief Forgets everything: the next call returns F(x) (e.g. when the map changed).
  void clear() {
    restart();
    m_started = false;
  }

 private:
  int m_depth;
  bool m_started = false;
  Eigen::VectorXd m_f_prev, m_r_prev;
  std::vector<Eigen::VectorXd> m_df, m_dr;
};

namespace fom {
using contactrom::AndersonMixer;  // the name it had when it lived in fom/
}  // namespace fom

}  // namespace contactrom
