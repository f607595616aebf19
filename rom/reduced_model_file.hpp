#pragma once
/// \file reduced_model_file.hpp
/// \brief A reduced model ready to query — the offline product (rom::ReducedModel),
/// its online method with the method's options, and the problem it reduces — and
/// its file: `contactrom reduce` writes one, `contactrom query` and Python's
/// `contactrom.ReducedModel.load` read it. Layout in docs/reduced_model_format.md.
///
/// Loading a file needs no FOM, no gmsh and no factorisation of the stiffness: the
/// problem is rebuilt from the stored problem-file text and mesh (assembly only,
/// for the contact search and the field reconstruction), the reduced operators are
/// read as stored.
///
/// \code
///   auto problem = std::shared_ptr<const fom::Problem>(rom::problem_from_database(db, "hertz30.h5"));
///   rom::OnlineModel rom(problem, db, {1e-8}, "greedy");
///   rom.save("hertz30_greedy.h5");
///   const rom::OnlineModel again = rom::OnlineModel::load("hertz30_greedy.h5");
///   const rom::OnlineResult res = again.solve(fom::Param::Constant(1, 0.1));
/// \endcode
#include <map>
#include <memory>
#include <string>

#include <contactrom/core/atomic_file.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/online_solver.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model.hpp>
#include <contactrom/rom/snapshot_database.hpp>

namespace contactrom::rom {

/// \brief Version of the reduced-model file layout (attribute `format_version`).
/// Version 3 names the offset kind `offset` (versions 1 and 2: `lifting`) and stores
/// the primal snapshots as the database does, u − u_lift (versions 1 and 2: u − u_off);
/// version 2 stores the snapshots' reduced coordinates and the primal snapshots only
/// for a method that needs them. Files of versions 1 and 2 are still read.
inline constexpr int kReducedModelFormatVersion = 3;

/// \brief A reduced model with its online method, ready to query; see the file comment.
/// Immutable after construction; solve() is thread-safe.
class OnlineModel {
 public:
  /// \brief Builds the reduced model from a database that matches `problem`
  /// (check_database) and the online method `method` on it.
  /// \throws InputError for an unknown method, a bad option or a database that does
  ///   not match.
  OnlineModel(std::shared_ptr<const fom::Problem> problem, const SnapshotDatabase& db,
              const ReducedModelOptions& model_options, const std::string& method,
              const OnlineSolverOptions& options = {});

  /// \brief Reads a file written by save().
  /// \throws InputError (one line naming `path`) if it is missing, not HDF5, not a
  ///   contactrom reduced model, of another format version, truncated or corrupt,
  ///   or inconsistent (sizes, non-finite values, a problem that does not rebuild to
  ///   the stored fingerprint).
  static OnlineModel load(const std::string& path);

  /// \brief Writes the model to `path` (HDF5, atomically: complete or not at all).
  /// \throws InputError naming `path` if the target is refused or cannot be written.
  void save(const std::string& path) const;

  const fom::Problem& problem() const { return *m_problem; }
  std::shared_ptr<const fom::Problem> shared_problem() const { return m_problem; }
  const ReducedModel& model() const { return *m_model; }
  const OnlineSolver& solver() const { return *m_solver; }
  const std::string& method() const { return m_method; }
  const OnlineSolverOptions& options() const { return m_options; }

  /// \brief One query: checks μ against the problem's range, then solves.
  /// \throws InputError for μ of the wrong size or outside the range.
  OnlineResult solve(const fom::Param& mu) const;

 private:
  OnlineModel(std::shared_ptr<const fom::Problem> problem, std::unique_ptr<ReducedModel> model,
              const std::string& method, const OnlineSolverOptions& options);

  std::shared_ptr<const fom::Problem> m_problem;
  std::unique_ptr<ReducedModel> m_model;
  std::string m_method;
  OnlineSolverOptions m_options;
  std::unique_ptr<OnlineSolver> m_solver;
};

/// \brief Parameters listed in a CSV file, one per line (values separated by commas,
/// one per parameter component; `#` comments and blank lines skipped; an optional
/// first line naming the components, e.g. `dx,dy`), each checked against the
/// problem's range. \throws InputError naming the file, the line and the value.
std::vector<fom::Param> read_parameter_csv(const std::string& path, const fom::Problem& problem);

struct FallbackAnswer;  // rom/fallback.hpp

/// \brief Writes one CSV row per query (atomically): one column per parameter (named
/// after it), then status, converged (0/1), iterations, sparsity, contact_force
/// (Σ weights · pressure), time_s (online core), selected (space-separated database
/// snapshot indices) and coefficients (space-separated, in the order of `selected`),
/// penetration, separation, primal_estimate and dual_estimate. With `fallback` (one
/// answer per result, from `query --fallback fom`), the columns of its JSON: source
/// (`rom` or `fom`), fallback_reason (empty when the ROM's answer was kept; quoted),
/// rom_status, rom_primal_estimate, rom_dual_estimate, rom_time_s and fom_time_s.
void write_query_csv(const std::string& path, const OnlineModel& rom, const std::vector<OnlineResult>& results,
                     const std::vector<FallbackAnswer>& fallback = {});

/// \brief The content of write_query_csv() (for a set of files published together).
FileWriter query_csv_writer(const OnlineModel& rom, const std::vector<OnlineResult>& results,
                            const std::vector<FallbackAnswer>& fallback = {});

}  // namespace contactrom::rom
