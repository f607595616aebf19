#pragma once
/// \file sampling.hpp
/// \brief Sampling plans: which parameters `offline` trains on and which ones
/// `online`/`verify` validate on, as given by a problem file's `[training]` and
/// `[validation]` tables.
///
/// Grids are tensor products over the parameters, the last parameter varying
/// fastest. One-dimensional point sets on a range [lo, hi] (or (lo, hi]):
///  - uniform N: closed range lo + (hi−lo)·i/(N−1), i = 0…N−1 (N ≥ 2);
///    open lower bound lo + (hi−lo)·i/N, i = 1…N (the hertz convention d_i = 0.3 i/N);
///  - nested level n: lo + (hi−lo)·i/2ⁿ, i = 0…2ⁿ (2ⁿ+1 points; i = 0 dropped when
///    the lower bound is open), so level n ⊂ level n+1;
///  - midpoints of the uniform set of size M: the M−1 midpoints of consecutive points;
///  - next level of level n: level n+1 minus level n (points with an odd index in
///    some parameter);
///  - random N, seed S: a Latin hypercube of N points (one per stratum and
///    parameter, seeded std::mt19937_64, so the same seed gives the same points);
///  - list: explicit points.
#include <string>
#include <vector>

#include <contactrom/fom/parameter_space.hpp>

namespace contactrom::fom {

/// \brief How a point set is drawn; see the file comment.
struct SamplingPlan {
  enum class Kind { Uniform, Nested, Random, List, Midpoints, NextLevel };
  Kind kind = Kind::Uniform;
  /// For Midpoints/NextLevel (and a validation Random's size): the size or level of the
  /// base set; 0 means "the training size or level" of the database at hand.
  int of = 0;
  unsigned seed = 0;          ///< Random: seed of the Latin hypercube
  std::vector<Param> points;  ///< List: the points
  /// Training size or level used when a command is given none (`bench`); 0: none.
  int default_size = 0;

  /// Name as written in a problem file ("uniform", "nested", ...).
  std::string kind_name() const;
  /// How `offline` selects a training set of this kind: "train" (`--train N`),
  /// "level" (`--level n`) or "list" (neither: the listed points).
  std::string selector() const;

  /// \brief The points of the plan for size/level `n` (ignored by List; for
  /// Midpoints/NextLevel `n` is the base when `of` is 0).
  /// \throws InputError naming `n` when it is out of range for the kind (N ≥ 1,
  /// level 0…20, at most kMaxPoints points).
  std::vector<Param> points_for(const ParameterSpace& space, int n) const;

  /// Largest point set a plan may produce.
  static constexpr long kMaxPoints = 10000000;
};

/// \brief The n of a training plan from the command-line flags: `--train N` for a
/// "train" plan, `--level n` for a "level" plan, neither for a "list" plan (n is
/// then the number of points). Without the flag, `default_size` when allowed.
/// \throws InputError naming the flag that is missing or does not apply.
int resolve_training_size(const SamplingPlan& plan, const std::string& problem_name, int train, int level,
                          bool allow_default);

/// \brief Parses a kind name. \throws InputError listing the valid names.
SamplingPlan::Kind sampling_kind_from_name(const std::string& name, bool validation);

}  // namespace contactrom::fom
