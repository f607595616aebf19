#pragma once
/// \file fallback.hpp
/// \brief A reduced model that knows when not to answer: a query whose reduced
/// answer is not `success`, or whose error estimates (rom/error_indicator.hpp),
/// times a safety factor, exceed the tolerances, is answered by the FOM instead.
/// The FOM is built from the reduced model's own problem (the mesh and problem
/// definition a database or reduced-model file carries), on the first query that
/// needs it.
///
/// \code
///   contactrom query --rom hertz30_greedy.h5 --params points.csv --fallback fom --out answers.csv
/// \endcode
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/rom/online_solver.hpp>

namespace contactrom::rom {

/// \brief Options of FallbackSolver (documented defaults).
struct FallbackOptions {
  /// Largest relative H¹ displacement error an answer kept from the ROM may have:
  /// kept when safety_factor × primal_estimate ≤ this. Default 0.05.
  double primal_tolerance = 0.05;
  /// Largest relative L²(Γc) pressure error of an answer kept from the ROM. Default 0.2.
  double dual_tolerance = 0.2;
  /// Factor on the estimates (they are sharp, not bounds: 3 × the estimate exceeds the
  /// true error on all but a few per cent of the measured queries; docs/results.md).
  /// Default 3.
  double safety_factor = 3.0;
  fom::ActiveSetOptions fom;  ///< options of the FOM solver
};

/// \brief Where an answer came from, and why.
struct FallbackAnswer {
  /// The answer: the ROM's, or (from_fom) the FOM's displacement, pressure, status and
  /// contact residuals, with time_s the ROM's and the FOM's time together, the
  /// estimates 0 (it is the reference) and no reduced coordinates (u_hat empty: the
  /// FOM's u is not in the basis).
  OnlineResult result;
  bool from_fom = false;   ///< the FOM answered
  std::string reason;      ///< why the ROM's answer was not kept (empty when it was)
  double rom_time_s = 0.0; ///< time of the reduced query (its estimate included)
  double fom_time_s = 0.0; ///< time of the FOM solve (0 when the ROM answered)
  /// The ROM's own estimates, kept when the FOM answered.
  double rom_primal_estimate = 0.0, rom_dual_estimate = 0.0;
  Status rom_status = Status::Success;  ///< the ROM's status
  /// A FOM answer's fom::solution_warnings (elements it turns inside out), as `fom`
  /// prints them; empty for a ROM answer.
  std::vector<std::string> warnings;
};

/// \brief The ROM, with the FOM behind it; see the file comment. solve() is thread-safe.
class FallbackSolver {
 public:
  /// \param rom an online solver that estimates its errors (make_online_solver with
  ///   the `estimate` option on); it and its model must outlive this object.
  /// \throws InputError for a solver with the estimate off, or a tolerance or safety
  ///   factor that is not a finite number > 0.
  FallbackSolver(const OnlineSolver& rom, FallbackOptions options = {});
  ~FallbackSolver();
  /// Whether the ROM's answer `res` is kept (status success, finite estimates within
  /// the tolerances); otherwise `reason` says why not.
  bool keeps(const OnlineResult& res, std::string& reason) const;
  /// \brief One query: the ROM's answer if kept, else the FOM's.
  FallbackAnswer solve(const fom::Param& mu) const;
  /// Time spent building the FOM (factorisation), 0 until a query needed it.
  double fom_setup_time() const;
  /// The tolerances it was made with.
  const FallbackOptions& options() const { return m_options; }

 private:
  const fom::ActiveSetSolver& fom_solver() const;
  const OnlineSolver& m_rom;
  FallbackOptions m_options;
  mutable std::once_flag m_once;
  mutable std::unique_ptr<fom::ActiveSetSolver> m_fom;
};

}  // namespace contactrom::rom
