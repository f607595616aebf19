#include <contactrom/core/anderson.hpp>

#include <algorithm>

namespace contactrom {

AndersonMixer::AndersonMixer(int depth, bool restart_on_growth)
    : m_depth(std::max(depth, 0)), m_restart_on_growth(restart_on_growth) {}

void AndersonMixer::reset(int depth) {
  clear();
  depth = std::max(depth, 0);
  if (depth != m_depth) m_depth = depth, m_df.resize(0, 0), m_dr.resize(0, 0);  // sized again by the next call
}

void AndersonMixer::size_for(Eigen::Index n) {
  if (m_df.rows() == n && m_df.cols() == m_depth) return;
  m_df.setZero(n, m_depth), m_dr.setZero(n, m_depth);
  m_gram.setIdentity(m_depth, m_depth);
  m_dots.setZero(m_depth, m_depth);
  m_rhs.setZero(m_depth), m_gamma.setZero(m_depth);
  m_ldlt.compute(m_gram);  // sizes its storage (the size-only constructor leaves its status unset)
  m_r.resize(n);
  clear();  // the history, if any, was of vectors of another length
}

void AndersonMixer::next(const Eigen::VectorXd& x, const Eigen::VectorXd& f, Eigen::VectorXd& out) {
  size_for(x.size());
  m_r = f - x;  // before `out` is written: it may be x
  const double r_norm = m_r.norm();
  if (m_started && m_depth > 0) {
    if (m_restart_on_growth && r_norm > m_r_prev_norm) restart();
    int slot;
    if (m_count < m_depth) {
      slot = (m_oldest + m_count) % m_depth, ++m_count;
    } else {  // full: the newest difference replaces the oldest
      slot = m_oldest, m_oldest = (m_oldest + 1) % m_depth;
    }
    m_df.col(slot) = f - m_f_prev;
    m_dr.col(slot) = m_r - m_r_prev;
    // The new difference's dot products with the ones held (itself included); the
    // others' are unchanged, so a step costs m_count dot products, not m_count².
    for (int a = 0; a < m_count; ++a) {
      const int other = (m_oldest + a) % m_depth;
      m_dots(slot, other) = m_dots(other, slot) = m_dr.col(slot).dot(m_dr.col(other));
    }
  }
  m_started = true;
  m_f_prev = f;
  m_r_prev = m_r;
  m_r_prev_norm = r_norm;
  if (m_count == 0) {
    if (&out != &f) out = f;
    return;
  }
  // Least-squares γ = argmin |r − ΔR γ| by the normal equations, oldest difference
  // first; the columns beyond m_count are the identity with a zero right-hand side.
  const auto column = [&](int a) { return (m_oldest + a) % m_depth; };
  m_gram.setIdentity();
  m_rhs.setZero();
  for (int a = 0; a < m_count; ++a) {
    m_rhs(a) = m_dr.col(column(a)).dot(m_r);
    for (int b = 0; b <= a; ++b) m_gram(a, b) = m_gram(b, a) = m_dots(column(a), column(b));
  }
  m_ldlt.compute(m_gram);
  m_gamma = m_ldlt.solve(m_rhs);
  if (&out != &f) out = f;
  if (m_ldlt.info() != Eigen::Success || !m_gamma.allFinite()) return;
  for (int a = 0; a < m_count; ++a) out.noalias() -= m_gamma(a) * m_df.col(column(a));
}

}  // namespace contactrom
