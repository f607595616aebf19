#include <contactrom/core/progress_bar.hpp>

#include <cstdio>
#include <ostream>

namespace contactrom {

ProgressBar::ProgressBar(std::ostream& out, std::string label, bool enabled)
    : m_out(out), m_label(std::move(label)), m_enabled(enabled), m_start(std::chrono::steady_clock::now()),
      m_last(m_start) {}

void ProgressBar::update(int done, int total) {
  if (!m_enabled || total <= 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (done < total && m_drawn && now - m_last < std::chrono::milliseconds(50)) return;
  m_last = now;
  const double elapsed = std::chrono::duration<double>(now - m_start).count();
  const double rate = elapsed > 0.0 ? done / elapsed : 0.0;
  const double eta = rate > 0.0 ? (total - done) / rate : 0.0;
  constexpr int width = 30;
  const int filled = static_cast<int>(static_cast<long long>(width) * done / total);
  std::string bar(filled, '#');
  bar += std::string(width - filled, '.');
  char text[160];
  if (done < total)
    std::snprintf(text, sizeof text, " [%s] %d/%d  %.1f/s  ETA %.1f s", bar.c_str(), done, total, rate, eta);
  else
    std::snprintf(text, sizeof text, " [%s] %d/%d  %.1f/s  %.1f s", bar.c_str(), done, total, rate, elapsed);
  // Trailing blanks erase a longer previous line; the line never wraps.
  m_out << '\r' << m_label << text << "   " << std::flush;
  m_drawn = true;
}

void ProgressBar::finish() {
  if (m_drawn) m_out << '\n' << std::flush;
  m_drawn = false;
}

}  // namespace contactrom
