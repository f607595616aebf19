#include <contactrom/core/lawson_hanson.hpp>

#include <algorithm>

namespace contactrom {

using Eigen::Index;
using Eigen::VectorXd;

namespace {

/// One run of the loop: the iterate, which variables are free or refused, and the
/// count of active-set changes.
class LawsonHansonLoop {
 public:
  LawsonHansonLoop(LawsonHansonProblem& problem, VectorXd& x, const LawsonHansonOptions& options)
      : m_problem(problem),
        m_x(x),
        m_options(options),
        m_is_free(static_cast<std::size_t>(x.size()), 0),
        m_refused(static_cast<std::size_t>(x.size()), 0) {
    for (const Index j : problem.passive()) m_is_free[static_cast<std::size_t>(j)] = 1;
  }

  LawsonHansonResult run() {
    bool solve_first = m_options.start_with_passive_solve;
    while (true) {
      if (!solve_first) {
        const Entry entry = free_best_variable();
        if (entry == Entry::Stop) break;
        if (entry == Entry::Refused) continue;
      }
      solve_first = false;
      if (!solve_on_passive_set()) break;
    }
    return m_result;
  }

 private:
  enum class Entry { Freed, Refused, Stop };

  /// Steps 1–2: the optimality test, then the bound variable of largest descent
  /// enters the passive set (or is refused when it cannot be freed).
  Entry free_best_variable() {
    const double threshold = m_problem.descent(m_x, m_w);
    Index best = -1;
    for (Index j = 0; j < m_x.size(); ++j) {
      const auto sj = static_cast<std::size_t>(j);
      if (m_is_free[sj] || m_refused[sj]) continue;
      if (best < 0 || m_w(j) > m_w(best)) best = j;
    }
    if (best < 0 || m_w(best) <= threshold) {
      m_result.status = m_problem.converged(m_w, m_refused);
      return Entry::Stop;
    }
    if (at_cap()) return Entry::Stop;
    ++m_result.iterations;
    if (!m_problem.free(best)) {
      m_refused[static_cast<std::size_t>(best)] = 1;
      return Entry::Refused;
    }
    m_is_free[static_cast<std::size_t>(best)] = 1;
    m_entering = best;
    return Entry::Freed;
  }

  /// Step 3: passive solves and feasibility steps until the passive solution is
  /// positive. Returns false when the loop must stop (failure or cap).
  bool solve_on_passive_set() {
    while (true) {
      if (!m_problem.solve_passive(m_z)) {
        m_result.status = Status::NumericalIssue;
        return false;
      }
      if (m_entering >= 0 && !keep_entering_variable()) return true;
      const auto& passive = m_problem.passive();
      if (m_z.size() == 0 || m_z.minCoeff() > 0.0) {
        for (std::size_t i = 0; i < passive.size(); ++i) m_x(passive[i]) = m_z(static_cast<Index>(i));
        return true;
      }
      if (at_cap()) return false;
      step_towards_passive_solution();
    }
  }

  /// Lawson–Hanson (Lemma 23.17): the entering variable is positive in the first
  /// passive solve in exact arithmetic. If rounding says otherwise, undo the entry
  /// instead of taking a zero-length step that would cycle.
  bool keep_entering_variable() {
    const Index j = m_entering;
    m_entering = -1;
    const Index last = m_z.size() - 1;
    if (!(m_z(last) > 0.0)) {
      m_problem.bind(last);
      m_is_free[static_cast<std::size_t>(j)] = 0;
      m_refused[static_cast<std::size_t>(j)] = 1;
      return false;
    }
    std::fill(m_refused.begin(), m_refused.end(), 0);
    return true;
  }

  /// Longest step from x towards z that keeps x ≥ 0; the blocking variable leaves
  /// the passive set, together with any other that fell to the bind tolerance.
  void step_towards_passive_solution() {
    const auto& passive = m_problem.passive();
    const auto k = static_cast<Index>(passive.size());
    double step = 1.0;
    Index blocking = -1;
    for (Index i = 0; i < k; ++i) {
      if (m_z(i) > 0.0) continue;
      const double xi = m_x(passive[static_cast<std::size_t>(i)]);
      const double ratio = xi / (xi - m_z(i));
      if (blocking < 0 || ratio < step) {
        step = ratio;
        blocking = i;
      }
    }
    for (Index i = 0; i < k; ++i) {
      const Index j = passive[static_cast<std::size_t>(i)];
      m_x(j) += step * (m_z(i) - m_x(j));
    }
    m_x(passive[static_cast<std::size_t>(blocking)]) = 0.0;
    for (Index i = k - 1; i >= 0; --i) {
      const Index j = passive[static_cast<std::size_t>(i)];
      if (m_x(j) > m_options.bind_tolerance) continue;
      m_x(j) = 0.0;
      m_is_free[static_cast<std::size_t>(j)] = 0;
      m_problem.bind(i);
      ++m_result.iterations;
    }
    std::fill(m_refused.begin(), m_refused.end(), 0);
  }

  bool at_cap() {
    if (m_result.iterations < m_options.max_iterations) return false;
    m_result.status = Status::NoConvergence;
    return true;
  }

  LawsonHansonProblem& m_problem;
  VectorXd& m_x;
  const LawsonHansonOptions& m_options;
  std::vector<char> m_is_free;
  /// Variables refused since the passive set last changed: numerically dependent on
  /// the passive ones, or whose first passive value came out non-positive.
  std::vector<char> m_refused;
  Index m_entering = -1;  ///< variable freed by the last entry, until its first solve
  VectorXd m_w;
  VectorXd m_z;
  LawsonHansonResult m_result;
};

}  // namespace

LawsonHansonResult lawson_hanson(LawsonHansonProblem& problem, VectorXd& x, const LawsonHansonOptions& options) {
  return LawsonHansonLoop(problem, x, options).run();
}

}  // namespace contactrom
