// contactrom sparse — runs one sparse regression kernel (core/nnls.hpp, rom/omp.hpp,
// rom/focuss.hpp) on a dictionary D and a signal x read from CSV files:
//
//   contactrom sparse --method nnls|omp|focuss|nnfocuss --dictionary D.csv --signal x.csv
//                     [--atoms K] [--tol E] [--max-iter N] [--json]
//
// D.csv: one dictionary row per line, comma-separated (m lines of n values).
// x.csv: m values, one per line or all on one line.
// --atoms: OMP only, largest number of atoms. --tol: NNLS relative KKT tolerance,
// OMP relative residual tolerance, FOCUSS/nnFOCUSS relative change tolerance.
// --max-iter: NNLS active-set changes, FOCUSS/nnFOCUSS re-weighted solves, OMP atoms.
// --json prints one object {method, status, iterations, residual, coefficients, ...};
// a numerical failure is reported as a status (exit 0), bad input exits 2.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <contactrom/core/format.hpp>
#include <contactrom/core/errors.hpp>
#include <contactrom/core/exact_scaling.hpp>
#include <contactrom/core/nnls.hpp>
#include <contactrom/rom/dense_csv.hpp>
#include <contactrom/rom/focuss.hpp>
#include <contactrom/rom/omp.hpp>
#include "tools/cli.hpp"
#include "tools/cli_common.hpp"

namespace {

using contactrom::InputError;
using contactrom::Status;
using Eigen::MatrixXd;
using Eigen::VectorXd;

struct SparseArgs {
  std::string method;
  std::string dictionary;
  std::string signal;
  int atoms = -1;
  double tolerance = 0.0;
  int max_iterations = 0;
  bool json = false;
};

struct SparseRun {
  Status status = Status::Success;
  int iterations = 0;
  VectorXd coefficients;
  nlohmann::json extra = nlohmann::json::object();  // method-specific keys
};

SparseRun run_method(const SparseArgs& args, bool has_tol, bool has_max_iter, bool has_atoms, const MatrixXd& d,
                     const VectorXd& x) {
  namespace rom = contactrom::rom;
  SparseRun run;
  if (args.method == "nnls") {
    contactrom::NnlsOptions options;
    if (has_tol) options.tolerance = args.tolerance;
    if (has_max_iter) options.max_iterations = args.max_iterations;
    contactrom::Nnls nnls(options);
    run.coefficients = nnls.compute(d).solve(x);
    run.status = nnls.info();
    run.iterations = nnls.iterations();
  } else if (args.method == "omp") {
    rom::OmpOptions options;
    if (has_tol) options.tolerance = args.tolerance;
    if (has_atoms) options.max_atoms = args.atoms;
    if (has_max_iter) options.max_atoms = has_atoms ? std::min(args.atoms, args.max_iterations) : args.max_iterations;
    rom::Omp omp(options);
    run.coefficients = omp.compute(d).solve(x);
    run.status = omp.info();
    run.iterations = omp.iterations();
    run.extra["stop_reason"] = rom::to_string(omp.stop_reason());
  } else {
    rom::FocussOptions options;
    if (has_tol) options.tolerance = args.tolerance;
    if (has_max_iter) options.max_iterations = args.max_iterations;
    if (args.method == "focuss") {
      rom::Focuss focuss(options);
      run.coefficients = focuss.compute(d).solve(x);
      run.status = focuss.info();
      run.iterations = focuss.iterations();
    } else {
      rom::NnFocuss nnfocuss(options);
      run.coefficients = nnfocuss.compute(d).solve(x);
      run.status = nnfocuss.info();
      run.iterations = nnfocuss.iterations();
      run.extra["relaxations"] = nnfocuss.relaxations();
      run.extra["nnls_iterations"] = nnfocuss.nnls().iterations();
      run.extra["nnls_status"] = contactrom::to_string(nnfocuss.nnls().info());
    }
  }
  return run;
}

/// NNLS, OMP and nnFOCUSS work with the n x n Gram matrix of the dictionary's
/// columns: refuse, naming the size, a dictionary whose Gram matrix cannot fit in
/// this machine's memory instead of failing inside the allocator.
void check_gram_fits(const SparseArgs& args, const MatrixXd& d) {
  if (args.method == "focuss") return;
  const double n = static_cast<double>(d.cols());
  const double bytes = n * n * sizeof(double);
  const double memory = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGE_SIZE));
  if (memory > 0.0 && bytes > 0.5 * memory) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "dictionary '%s' has %lld columns: %s works with their %lld x %lld Gram matrix (%.3g GB), more than "
                  "half of this machine's %.3g GB of memory; expected at most %lld columns",
                  args.dictionary.c_str(), static_cast<long long>(d.cols()), args.method.c_str(),
                  static_cast<long long>(d.cols()), static_cast<long long>(d.cols()), bytes / 1e9, memory / 1e9,
                  static_cast<long long>(std::sqrt(0.5 * memory / sizeof(double))));
    throw InputError(text);
  }
}

void run_sparse(const SparseArgs& args, bool has_tol, bool has_max_iter, bool has_atoms) {
  if (args.method != "nnls" && args.method != "omp" && args.method != "focuss" && args.method != "nnfocuss") {
    throw InputError("unknown --method " + contactrom::quoted(args.method, 200) + ": expected nnls, omp, focuss or nnfocuss");
  }
  if (has_atoms && args.method != "omp") {
    throw InputError("--atoms " + std::to_string(args.atoms) + " given with --method " + args.method +
                     ": --atoms applies to --method omp only");
  }
  if (has_atoms && args.atoms < 0) {
    throw InputError("--atoms " + std::to_string(args.atoms) + ": expected a number of atoms >= 0");
  }
  if (has_tol && !(std::isfinite(args.tolerance) && args.tolerance >= 0.0)) {
    throw InputError("--tol " + std::to_string(args.tolerance) + ": expected a finite tolerance >= 0");
  }
  if (has_max_iter && args.max_iterations < 1) {
    throw InputError("--max-iter " + std::to_string(args.max_iterations) + ": expected an iteration cap >= 1");
  }
  const MatrixXd d = contactrom::rom::read_dense_csv(args.dictionary);
  const VectorXd x = contactrom::rom::read_vector_csv(args.signal);
  if (x.size() != d.rows()) {
    throw InputError("signal " + contactrom::quoted(args.signal, 200) + " has " + std::to_string(x.size()) + " values, expected " +
                     std::to_string(d.rows()) + " (the rows of dictionary " + contactrom::quoted(args.dictionary, 200) + ")");
  }

  check_gram_fits(args, d);
  // Data of extreme magnitude is scaled by powers of two (exact) for the kernel.
  const SparseRun run = contactrom::solve_exactly_scaled(
      d, x, [&](const MatrixXd& ds, const VectorXd& xs) { return run_method(args, has_tol, has_max_iter, has_atoms, ds, xs); },
      [](SparseRun& r) -> VectorXd& { return r.coefficients; });
  const auto [residual, relative] = contactrom::residual_norms(d, run.coefficients, x);
  std::vector<Eigen::Index> nonzeros;
  for (Eigen::Index j = 0; j < run.coefficients.size(); ++j) {
    if (run.coefficients(j) != 0.0) nonzeros.push_back(j);
  }

  if (args.json) {
    nlohmann::json out;
    out["method"] = args.method;
    out["status"] = contactrom::to_string(run.status);
    out["iterations"] = run.iterations;
    out["residual"] = residual;
    out["relative_residual"] = relative;
    out["nonzeros"] = nonzeros.size();
    out["rows"] = d.rows();
    out["cols"] = d.cols();
    out["coefficients"] = std::vector<double>(run.coefficients.data(), run.coefficients.data() + run.coefficients.size());
    for (const auto& item : run.extra.items()) out[item.key()] = item.value();
    std::cout << contactrom::cli::json_text(out) << "\n";  // doubles are written with round-trip precision
    return;
  }

  std::cout << "contactrom sparse: " << args.method << " on " << d.rows() << "x" << d.cols() << " dictionary '"
            << args.dictionary << "'\n";
  std::cout << "  status      " << contactrom::to_string(run.status) << " after " << run.iterations << " iterations\n";
  std::cout << std::setprecision(6);
  std::cout << "  residual    ||D a - x|| = " << residual << " (relative " << relative << ")\n";
  std::cout << "  non-zeros   " << nonzeros.size() << " of " << run.coefficients.size() << "\n";
  constexpr std::size_t shown = 20;
  std::cout << std::setprecision(10);
  for (std::size_t i = 0; i < nonzeros.size() && i < shown; ++i) {
    std::cout << "    a[" << nonzeros[i] << "] = " << run.coefficients(nonzeros[i]) << "\n";
  }
  if (nonzeros.size() > shown) std::cout << "    ... (" << nonzeros.size() - shown << " more; use --json)\n";
}

const contactrom::cli::CommandRegistrar registrar("sparse", [](CLI::App& app) {
  auto args = std::make_shared<SparseArgs>();
  auto* sub = app.add_subcommand("sparse", "Sparse regression of a signal on a dictionary (NNLS, OMP, FOCUSS, nnFOCUSS)");
  sub->add_option("--method", args->method, "nnls | omp | focuss | nnfocuss")->required();
  sub->add_option("--dictionary", args->dictionary, "CSV file of D (one row per line)")
      ->check(contactrom::cli::non_empty_path())->required();
  sub->add_option("--signal", args->signal, "CSV file of x (one column or one row)")
      ->check(contactrom::cli::non_empty_path())->required();
  using contactrom::Interval;
  using contactrom::cli::add_integer;
  using contactrom::cli::add_number;
  auto* atoms = add_integer(sub, "--atoms", args->atoms, "OMP: largest number of atoms (default min(rows, cols))", 0,
                            100000000);
  auto* tol = add_number(sub, "--tol", args->tolerance,
                         "tolerance: NNLS KKT (1e-12), OMP relative residual (1e-8), FOCUSS change (1e-10)",
                         Interval::at_least(0));
  auto* max_iter = add_integer(sub, "--max-iter", args->max_iterations,
                               "iteration cap: NNLS active-set changes (3n), FOCUSS solves (100), OMP atoms", 1,
                               100000000);
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->callback([args, atoms, tol, max_iter] {
    run_sparse(*args, tol->count() > 0, max_iter->count() > 0, atoms->count() > 0);
  });
});

}  // namespace
