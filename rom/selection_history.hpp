#pragma once
/// \file selection_history.hpp
/// \brief The selections (sets of dual-basis columns) an online active set has met,
/// to detect a cycle of its steps on frozen operators.
#include <algorithm>
#include <vector>

namespace contactrom::rom {

/// Selections met one after the other (each stored sorted), to detect a cycle of
/// active-set steps. Its storage only grows, so clearing it does not free.
class SelectionHistory {
 public:
  void clear() { m_seen.clear(), m_start.assign(1, 0); }
  bool empty() const { return m_start.size() == 1; }
  /// Whether `selection` (any order) was met since the last clear(); records it if not.
  template <class Columns, class Index>
  bool revisits(const Columns& selection, Index index) {
    m_key.clear();
    for (const auto& c : selection) m_key.push_back(index(c));
    std::sort(m_key.begin(), m_key.end());
    for (size_t e = 0; e + 1 < m_start.size(); ++e)
      if (std::equal(m_key.begin(), m_key.end(), m_seen.begin() + m_start[e], m_seen.begin() + m_start[e + 1]))
        return true;
    m_seen.insert(m_seen.end(), m_key.begin(), m_key.end());
    m_start.push_back(static_cast<int>(m_seen.size()));
    return false;
  }

 private:
  std::vector<int> m_seen, m_start{0}, m_key;
};

}  // namespace contactrom::rom
