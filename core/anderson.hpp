#pragma once
/// \file anderson.hpp
/// \brief Anderson acceleration (Walker & Ni 2011, "type II", restarted) of a fixed
/// point x = F(x), shared by the contact-pairing loops of the FOM and ROM solvers.
#include <Eigen/Cholesky>
#include <Eigen/Dense>

namespace contactrom {

/// \brief Keeps the last `depth` differences of the iterates and their residuals
/// r = F(x) − x, and extrapolates x_next = F(x) − ΔF γ with γ = argmin |r − ΔR γ|
/// (normal equations, a pivoted LDLᵀ drops dependent differences). By default the
/// history is cleared whenever the residual grows.
///
/// The differences live in two n × depth matrices used as ring buffers, and the
/// normal equations are always depth × depth (the unused part is the identity with
/// a zero right-hand side, so its coefficients are zero): once the first call has
/// sized them for vectors of length n, next(x, f, out) allocates no memory.
class AndersonMixer {
 public:
  /// \param depth number of differences kept (0: plain fixed-point iteration)
  /// \param restart_on_growth clear the differences when |F(x) − x| grows (default);
  ///   false keeps them (the FOM's pairing fixed point, whose early iterates jump)
  explicit AndersonMixer(int depth, bool restart_on_growth = true);

  /// \brief The next iterate into `out`, given the current one `x` and its image
  /// `f` = F(x). `out` may be `x` or `f`.
  void next(const Eigen::VectorXd& x, const Eigen::VectorXd& f, Eigen::VectorXd& out);
  /// \returns the next iterate (as next(x, f, out), into a new vector).
  Eigen::VectorXd next(const Eigen::VectorXd& x, const Eigen::VectorXd& f) {
    Eigen::VectorXd out;
    next(x, f, out);
    return out;
  }

  /// \brief Drops the differences but keeps the last point: the next call mixes
  /// with that point only (e.g. after an extrapolation the caller rejected).
  void restart() { m_count = 0, m_oldest = 0; }
  /// \brief Forgets everything: the next call returns F(x) (e.g. when the map changed).
  void clear() {
    restart();
    m_started = false;
  }
  /// \brief clear() with a new depth; the storage is kept when the depth is unchanged.
  void reset(int depth);

 private:
  void size_for(Eigen::Index n);

  int m_depth;
  bool m_restart_on_growth = true;
  int m_count = 0;   // differences held
  int m_oldest = 0;  // ring-buffer column of the oldest one
  bool m_started = false;
  Eigen::VectorXd m_f_prev, m_r_prev, m_r;
  Eigen::MatrixXd m_df, m_dr;  // n × depth ring buffers of ΔF and ΔR
  Eigen::MatrixXd m_gram;      // depth × depth normal equations
  Eigen::MatrixXd m_dots;      // depth × depth ΔR dot products by ring-buffer column
  double m_r_prev_norm = 0.0;  // |m_r_prev|
  Eigen::VectorXd m_rhs, m_gamma;
  Eigen::LDLT<Eigen::MatrixXd> m_ldlt;
};


}  // namespace contactrom
