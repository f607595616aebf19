#pragma once
/// \file progress_bar.hpp
/// \brief A one-line text progress bar for long loops (offline snapshots, verification).
#include <chrono>
#include <iosfwd>
#include <string>

namespace contactrom {

/// \brief A one-line progress bar "label [#####.....] 17/30  42.1/s  ETA 0.3 s"
/// redrawn in place with a carriage return. It draws only when enabled (the CLI enables it
/// when stderr is a terminal or with --progress); finish() ends the line.
class ProgressBar {
 public:
  ProgressBar(std::ostream& out, std::string label, bool enabled);
  /// Redraws with `done` of `total` completed (throttled to ~20 redraws/s, and
  /// always drawn for the last one).
  void update(int done, int total);
  /// Ends the line (prints '\n') if anything was drawn.
  void finish();

 private:
  std::ostream& m_out;
  std::string m_label;
  bool m_enabled;
  bool m_drawn = false;
  std::chrono::steady_clock::time_point m_start, m_last;
};


}  // namespace contactrom
