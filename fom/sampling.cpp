#include <contactrom/fom/sampling.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <contactrom/core/format.hpp>
#include <contactrom/core/errors.hpp>

namespace contactrom::fom {
namespace {

using Axis = std::vector<double>;

/// The point k of n equal steps from lo to hi: exactly lo at k = 0 and hi at k = n,
/// and never outside [lo, hi] in between (lo + (hi − lo)·k/n alone can step past a
/// bound: 0.1·6/6 = 0.10000000000000002).
double grid_point(double lo, double hi, double k, double n) {
  if (k <= 0.0) return lo;
  if (k >= n) return hi;
  return std::clamp(lo + (hi - lo) * k / n, lo, hi);
}

Axis uniform_axis(const ParameterSpace& s, int i, int n) {
  const double lo = s.lower(i), hi = s.upper(i);
  Axis out;
  if (s.lower_open[i]) {
    for (int k = 1; k <= n; ++k) out.push_back(grid_point(lo, hi, k, n));
  } else if (n == 1) {
    out.push_back(lo);
  } else {
    for (int k = 0; k < n; ++k) out.push_back(grid_point(lo, hi, k, n - 1));
  }
  return out;
}

Axis midpoint_axis(const ParameterSpace& s, int i, int m) {
  const double lo = s.lower(i), hi = s.upper(i);
  Axis out;
  if (s.lower_open[i]) {
    for (int k = 1; k < m; ++k) out.push_back(grid_point(lo, hi, k + 0.5, m));
  } else {
    for (int k = 0; k + 1 < m; ++k) out.push_back(grid_point(lo, hi, k + 0.5, m - 1));
  }
  return out;
}

/// Level-`level` nodes with their integer index k (of 2^level).
std::vector<std::pair<long, double>> nested_axis(const ParameterSpace& s, int i, int level) {
  const long n = 1L << level;
  std::vector<std::pair<long, double>> out;
  for (long k = s.lower_open[i] ? 1 : 0; k <= n; ++k)
    out.emplace_back(k, grid_point(s.lower(i), s.upper(i), static_cast<double>(k), static_cast<double>(n)));
  return out;
}

long checked_product(const std::vector<long>& sizes) {
  long total = 1;
  for (long n : sizes) {
    if (n > 0 && total > SamplingPlan::kMaxPoints / n)
      throw InputError("the sampling plan would hold more than " + std::to_string(SamplingPlan::kMaxPoints) +
                       " points; expected a smaller size or level");
    total *= n;
  }
  return total;
}

/// Tensor grid of per-parameter axes, the last parameter varying fastest.
std::vector<Param> tensor(const std::vector<Axis>& axes) {
  std::vector<long> sizes;
  for (const Axis& a : axes) sizes.push_back(static_cast<long>(a.size()));
  const long total = checked_product(sizes);
  std::vector<Param> out;
  out.reserve(static_cast<size_t>(total));
  std::vector<size_t> idx(axes.size(), 0);
  for (long t = 0; t < total; ++t) {
    Param p(static_cast<Eigen::Index>(axes.size()));
    for (size_t d = 0; d < axes.size(); ++d) p(static_cast<Eigen::Index>(d)) = axes[d][idx[d]];
    out.push_back(p);
    for (size_t d = axes.size(); d-- > 0;) {
      if (++idx[d] < axes[d].size()) break;
      idx[d] = 0;
    }
  }
  return out;
}

void check_size(int n, const char* what) {
  if (n < 1 || n > SamplingPlan::kMaxPoints)
    throw InputError(std::string(what) + " " + std::to_string(n) + " is invalid; expected 1.." +
                     std::to_string(SamplingPlan::kMaxPoints));
}

void check_level(int level) {
  if (level < 0 || level > 20)
    throw InputError("level " + std::to_string(level) + " is invalid; expected 0..20");
}

}  // namespace

int resolve_training_size(const SamplingPlan& plan, const std::string& problem_name, int train, int level,
                          bool allow_default) {
  const std::string sel = plan.selector();
  const std::string intro = "problem " + quoted(problem_name, 200) + " ";
  if (sel == "list") {
    if (train || level)
      throw InputError(intro + "trains on its " + std::to_string(plan.points.size()) +
                       " listed points; expected neither --train nor --level");
    return static_cast<int>(plan.points.size());
  }
  const bool by_level = sel == "level";
  if (by_level ? train != 0 : level != 0)
    throw InputError(intro + "selects its training set with " + (by_level ? "--level n, not --train" : "--train N, not --level"));
  const int n = by_level ? level : train;
  if (n != 0) return n;
  if (allow_default && plan.default_size > 0) return plan.default_size;
  throw InputError(intro + "needs " + (by_level ? "--level n" : "--train N") +
                   (allow_default ? " (its file's [training] sets no default_size)" : ""));
}

std::string SamplingPlan::kind_name() const {
  switch (kind) {
    case Kind::Uniform: return "uniform";
    case Kind::Nested: return "nested";
    case Kind::Random: return "random";
    case Kind::List: return "list";
    case Kind::Midpoints: return "midpoints";
    case Kind::NextLevel: return "next_level";
  }
  return "?";
}

std::string SamplingPlan::selector() const {
  if (kind == Kind::Nested || kind == Kind::NextLevel) return "level";
  if (kind == Kind::List) return "list";
  return "train";
}

SamplingPlan::Kind sampling_kind_from_name(const std::string& name, bool validation) {
  using K = SamplingPlan::Kind;
  if (name == "uniform") return K::Uniform;
  if (name == "nested") return K::Nested;
  if (name == "random") return K::Random;
  if (name == "list") return K::List;
  if (validation && name == "midpoints") return K::Midpoints;
  if (validation && name == "next_level") return K::NextLevel;
  throw InputError("sampling " + quoted(name, 200) + " is unknown; expected one of: " +
                   (validation ? "midpoints, next_level, uniform, nested, random, list" : "uniform, nested, random, list"));
}

std::vector<Param> SamplingPlan::points_for(const ParameterSpace& space, int n) const {
  const int d = space.size();
  const int base = of > 0 ? of : n;
  std::vector<Axis> axes;
  switch (kind) {
    case Kind::List:
      return points;
    case Kind::Uniform:
      check_size(n, "training size");
      for (int i = 0; i < d; ++i) axes.push_back(uniform_axis(space, i, n));
      return tensor(axes);
    case Kind::Midpoints:
      check_size(base, "size of the uniform set");
      if (base < 2) throw InputError("midpoints of a uniform set of size " + std::to_string(base) + " is empty; expected a size of at least 2");
      for (int i = 0; i < d; ++i) axes.push_back(midpoint_axis(space, i, base));
      return tensor(axes);
    case Kind::Nested:
    case Kind::NextLevel: {
      const int level = kind == Kind::Nested ? n : base + 1;
      check_level(kind == Kind::Nested ? n : base);
      std::vector<std::vector<std::pair<long, double>>> nodes;
      std::vector<long> sizes;
      for (int i = 0; i < d; ++i) {
        nodes.push_back(nested_axis(space, i, level));
        sizes.push_back(static_cast<long>(nodes.back().size()));
      }
      const long total = checked_product(sizes);
      std::vector<Param> out;
      std::vector<size_t> idx(static_cast<size_t>(d), 0);
      for (long t = 0; t < total; ++t) {
        Param p(d);
        bool odd = false;
        for (int i = 0; i < d; ++i) {
          p(i) = nodes[i][idx[i]].second;
          odd = odd || (nodes[i][idx[i]].first % 2 == 1);
        }
        if (kind == Kind::Nested || odd) out.push_back(p);
        for (int i = d; i-- > 0;) {
          if (++idx[i] < nodes[i].size()) break;
          idx[i] = 0;
        }
      }
      return out;
    }
    case Kind::Random: {
      check_size(base, "number of random points");
      std::mt19937_64 rng(seed);
      std::uniform_real_distribution<double> unit(0.0, 1.0);
      std::vector<Param> out(static_cast<size_t>(base), Param(d));
      for (int i = 0; i < d; ++i) {
        std::vector<int> strata(static_cast<size_t>(base));
        std::iota(strata.begin(), strata.end(), 0);
        std::shuffle(strata.begin(), strata.end(), rng);
        for (int k = 0; k < base; ++k) {
          double t = (strata[static_cast<size_t>(k)] + unit(rng)) / base;
          if (space.lower_open[i] && t == 0.0) t = 0.5 / base;
          out[static_cast<size_t>(k)](i) = grid_point(space.lower(i), space.upper(i), t, 1.0);
        }
      }
      return out;
    }
  }
  return {};
}

}  // namespace contactrom::fom
