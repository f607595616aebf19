#include "core/anderson.hpp"

#include <algorithm>

namespace contactrom {

AndersonMixer::AndersonMixer(int depth) : m_depth(std::max(depth, 0)) {}

Eigen::VectorXd AndersonMixer::next(const Eigen::VectorXd& x, const Eigen::VectorXd& f) {
  const Eigen::VectorXd r = f - x;
  if (m_started) {
    if (r.norm() > m_r_prev.norm()) m_df.clear(), m_dr.clear();  // restart on growth
    m_df.push_back(f - m_f_prev);
    m_dr.push_back(r - m_r_prev);
    if (static_cast<int>(m_df.size()) > m_depth) m_df.erase(m_df.begin()), m_dr.erase(m_dr.begin());
  }
  m_started = true;
  m_f_prev = f;
  m_r_prev = r;
  Eigen::VectorXd out = f;
  if (m_dr.empty()) return out;
  // Least-squares γ = argmin |r − ΔR γ| by the normal equations (at most `depth`
  // columns; a pivoted LDLᵀ drops dependent differences).
  const int m = static_cast<int>(m_dr.size());
  Eigen::MatrixXd gram(m, m);
  Eigen::VectorXd rhs(m);
  for (int a = 0; a < m; ++a) {
    rhs(a) = m_dr[a].dot(r);
    for (int b = 0; b <= a; ++b) gram(a, b) = gram(b, a) = m_dr[a].dot(m_dr[b]);
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(gram);
  const Eigen::VectorXd gamma = ldlt.solve(rhs);
  if (ldlt.info() != Eigen::Success || !gamma.allFinite()) return out;
  for (int a = 0; a < m; ++a) out.noalias() -= gamma(a) * m_df[a];
  return out;
}

}  // namespace contactrom
