// Solves the `hertz` problem with the full-order model and with reduced models
// built from 12 snapshots (offline in memory), then compares them at one query.
//   hertz_rom [PROBLEM] [D]    PROBLEM: a shipped name or a .toml path (default hertz)
// Shipped problems are looked up in the installed package's data folder
// (contactrom_DATA_DIR of find_package(contactrom), passed by CMakeLists.txt as
// CONTACTROM_DATA_DIR), unless CONTACTROM_PROBLEM_DIR / CONTACTROM_MESH_DIR say
// otherwise. Errors end the program as a user's program would: bad input (an
// unknown problem, a parameter out of range) with its one-line message and code 2.
#include <cstdlib>
#include <exception>
#include <iostream>

#include <contactrom/core/errors.hpp>
#include <contactrom/fom/active_set_solver.hpp>
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/online_methods.hpp>
#include <contactrom/rom/reduced_model.hpp>

namespace {

int run(int argc, char** argv) {
  using namespace contactrom;
  const auto problem = fom::make_problem(argc > 1 ? argv[1] : "hertz");
  const fom::Param mu = fom::parse_param(*problem, argc > 2 ? argv[2] : "0.1275");

  const fom::ActiveSetSolver fom_solver(*problem);  // factorises K once
  const fom::FomSolution ref = fom_solver.solve(mu);
  std::cout << "FOM: " << to_string(ref.status) << ", contact force " << fom::contact_force(*problem, ref.lambda)
            << "\n";

  const rom::SnapshotDatabase db = rom::generate_snapshots(*problem, 12);  // offline, in memory
  rom::ReducedModelOptions model_options;
  model_options.delta = 1e-8;
  const rom::ReducedModel model(*problem, db, model_options);
  for (const char* method : {"greedy", "cpg"}) {
    const auto solver = rom::make_online_solver(method, model);
    const rom::OnlineResult r = solver->solve(mu);
    std::cout << "ROM " << method << ": " << to_string(r.status) << ", contact force "
              << fom::contact_force(*problem, r.lambda) << ", primal H1 error "
              << fom::relative_h1_error(*problem, r.u, ref.u) << ", dual L2 error "
              << fom::relative_l2_pressure_error(*problem, r.lambda, ref.lambda) << ", |I| = " << r.selected.size()
              << ", " << r.time_s * 1e6 << " us\n";
  }
  return ref.status == Status::Success ? EXIT_SUCCESS : EXIT_FAILURE;
}

}  // namespace

int main(int argc, char** argv) {
#ifdef CONTACTROM_DATA_DIR
  setenv("CONTACTROM_PROBLEM_DIR", CONTACTROM_DATA_DIR "/problems", /*overwrite=*/0);
  setenv("CONTACTROM_MESH_DIR", CONTACTROM_DATA_DIR "/meshes", 0);
#endif
  try {
    return run(argc, argv);
  } catch (const contactrom::InputError& e) {
    std::cerr << "hertz_rom: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "hertz_rom: error: " << e.what() << "\n";
    return 1;
  }
}
