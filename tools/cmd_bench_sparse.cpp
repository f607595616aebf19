// contactrom bench-sparse — micro-benchmark of the sparse regression kernels
// (NNLS, OMP, FOCUSS, nnFOCUSS) on seeded random Gaussian dictionaries of sizes
// 79x30, 200x129 and 2000x500 with planted sparse non-negative signals:
//
//   contactrom bench-sparse [--json] [--repeats N] [--noise E]
//
// For each kernel two per-call medians are reported: `call` = construct +
// compute(D) + solve(x) (dictionary analysis included), `solve` = solve(x) alone
// with compute(D) done once (the online situation: one dictionary, many signals).
// Results are recorded in docs/sparse_kernels.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/nnls.hpp>
#include <contactrom/rom/focuss.hpp>
#include <contactrom/rom/omp.hpp>
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace {

using contactrom::Status;
using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;
namespace rom = contactrom::rom;

struct BenchArgs {
  bool json = false;
  int repeats = 7;
  double noise = 0.0;
};

struct Problem {
  MatrixXd d;
  VectorXd x;
  Index planted = 0;
};

/// Gaussian dictionary (entries N(0,1)) and x = D a with a planted non-negative
/// a of max(3, n/10) entries in [1, 2], plus optional relative Gaussian noise.
Problem make_problem(Index m, Index n, double noise, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(1.0, 2.0);
  Problem p;
  p.d.resize(m, n);
  for (Index i = 0; i < p.d.size(); ++i) p.d(i) = normal(gen);
  p.planted = std::max<Index>(3, n / 10);
  std::vector<Index> columns(static_cast<std::size_t>(n));
  for (Index j = 0; j < n; ++j) columns[static_cast<std::size_t>(j)] = j;
  std::shuffle(columns.begin(), columns.end(), gen);
  VectorXd a = VectorXd::Zero(n);
  for (Index i = 0; i < p.planted; ++i) a(columns[static_cast<std::size_t>(i)]) = uniform(gen);
  p.x = p.d * a;
  if (noise > 0.0) {
    VectorXd e(m);
    for (Index i = 0; i < m; ++i) e(i) = normal(gen);
    p.x += noise * p.x.norm() / e.norm() * e;
  }
  return p;
}

/// Median over `repeats` samples of the time per call of f; each sample times a
/// batch of calls long enough (>= 2 ms) for the clock resolution not to matter.
double median_seconds(const std::function<void()>& f, int repeats) {
  using clock = std::chrono::steady_clock;
  const auto time_batch = [&](int count) {
    const auto start = clock::now();
    for (int i = 0; i < count; ++i) f();
    return std::chrono::duration<double>(clock::now() - start).count();
  };
  const double single = time_batch(1);  // also warms caches and allocations
  constexpr double min_batch_seconds = 2e-3;
  const int batch = single >= min_batch_seconds ? 1 : static_cast<int>(std::ceil(min_batch_seconds / std::max(single, 1e-9)));
  std::vector<double> samples;
  for (int r = 0; r < repeats; ++r) samples.push_back(time_batch(batch) / batch);
  std::nth_element(samples.begin(), samples.begin() + static_cast<long>(samples.size() / 2), samples.end());
  return samples[samples.size() / 2];
}

struct KernelResult {
  std::string kernel;
  double call_s = 0.0;
  double solve_s = 0.0;
  int iterations = 0;
  Index nonzeros = 0;
  double relative_residual = 0.0;
  Status status = Status::Success;
};

/// Times one kernel type: Solver has compute(D), solve(x), info(), iterations().
template <class Solver, class Options>
KernelResult bench_kernel(const std::string& name, const Options& options, const Problem& p, int repeats) {
  KernelResult r;
  r.kernel = name;
  r.call_s = median_seconds(
      [&] {
        Solver solver(options);
        VectorXd a = solver.compute(p.d).solve(p.x);
        (void)a;
      },
      repeats);
  Solver solver(options);
  solver.compute(p.d);
  VectorXd a;
  r.solve_s = median_seconds([&] { a = solver.solve(p.x); }, repeats);
  r.iterations = solver.iterations();
  r.status = solver.info();
  r.nonzeros = static_cast<Index>((a.array() != 0.0).count());
  r.relative_residual = (p.d * a - p.x).norm() / p.x.norm();
  return r;
}

void run_bench(const BenchArgs& args) {
  if (args.repeats < 1) {
    throw contactrom::InputError("--repeats " + std::to_string(args.repeats) + ": expected a count >= 1");
  }
  if (!(std::isfinite(args.noise) && args.noise >= 0.0)) {
    throw contactrom::InputError("--noise " + std::to_string(args.noise) + ": expected a finite relative level >= 0");
  }
  struct Size {
    Index m, n;
  };
  const std::vector<Size> sizes = {{79, 30}, {200, 129}, {2000, 500}};
  constexpr unsigned base_seed = 20240611u;

  nlohmann::json results = nlohmann::json::array();
  if (!args.json) {
    std::cout << "contactrom bench-sparse: median seconds per call (" << args.repeats << " samples), noise "
              << args.noise << "\n";
    std::cout << std::left << std::setw(10) << "size" << std::setw(10) << "kernel" << std::setw(8) << "planted"
              << std::right << std::setw(12) << "call [s]" << std::setw(12) << "solve [s]" << std::setw(7) << "iter"
              << std::setw(6) << "nnz" << std::setw(11) << "rel.res" << "  status\n";
  }
  for (std::size_t s = 0; s < sizes.size(); ++s) {
    const Problem p = make_problem(sizes[s].m, sizes[s].n, args.noise, base_seed + static_cast<unsigned>(s));
    std::vector<KernelResult> kernels;
    kernels.push_back(bench_kernel<contactrom::Nnls>("nnls", contactrom::NnlsOptions{}, p, args.repeats));
    kernels.push_back(bench_kernel<rom::Omp>("omp", rom::OmpOptions{}, p, args.repeats));
    kernels.push_back(bench_kernel<rom::Focuss>("focuss", rom::FocussOptions{}, p, args.repeats));
    kernels.push_back(bench_kernel<rom::NnFocuss>("nnfocuss", rom::FocussOptions{}, p, args.repeats));
    const std::string size = std::to_string(sizes[s].m) + "x" + std::to_string(sizes[s].n);
    for (const auto& k : kernels) {
      if (args.json) {
        results.push_back({{"rows", sizes[s].m}, {"cols", sizes[s].n}, {"planted", p.planted}, {"kernel", k.kernel},
                           {"call_median_s", k.call_s}, {"solve_median_s", k.solve_s}, {"iterations", k.iterations},
                           {"nonzeros", k.nonzeros}, {"relative_residual", k.relative_residual},
                           {"status", contactrom::to_string(k.status)}});
      } else {
        std::cout << std::left << std::setw(10) << size << std::setw(10) << k.kernel << std::setw(8) << p.planted
                  << std::right << std::scientific << std::setprecision(2) << std::setw(12) << k.call_s
                  << std::setw(12) << k.solve_s << std::setw(7) << k.iterations << std::setw(6) << k.nonzeros
                  << std::setw(11) << std::setprecision(1) << k.relative_residual << "  "
                  << contactrom::to_string(k.status) << "\n"
                  << std::defaultfloat;
      }
    }
  }
  if (args.json) {
    nlohmann::json out;
    out["repeats"] = args.repeats;
    out["noise"] = args.noise;
    out["seed"] = base_seed;
    out["results"] = results;
    std::cout << contactrom::cli::json_text(out) << "\n";
  }
}

const contactrom::cli::CommandRegistrar registrar("bench-sparse", [](CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  auto* sub = app.add_subcommand("bench-sparse", "Micro-benchmark of the NNLS, OMP, FOCUSS and nnFOCUSS kernels");
  sub->add_flag("--json", args->json, "print one JSON object");
  contactrom::cli::add_integer(sub, "--repeats", args->repeats, "timing samples per kernel, median reported (default 7)",
                               1, 1000);
  contactrom::cli::add_number(sub, "--noise", args->noise, "relative Gaussian noise added to the planted signals (default 0)",
                              contactrom::Interval::at_least(0));
  sub->callback([args] { run_bench(*args); });
});

}  // namespace
