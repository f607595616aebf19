// The reduced-model file (rom/reduced_model_file.hpp, `reduce`, `query`): a saved
// and loaded model answers every query exactly as the model it was saved from
// (same selections, bitwise the same coefficients and fields), for each online
// method; `query` from the CLI gives the same answers as the library; damaged or
// wrong files are refused with one line naming the file.
#define BOOST_TEST_MODULE rom_reduced_model_file
#include <boost/test/unit_test.hpp>

#include <hdf5.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/cli_blas_threads.hpp"
#include "common/database_checks.hpp"
#include "common/run_command.hpp"
#include <contactrom/fom/kkt.hpp>
#include <contactrom/fom/problem.hpp>
#include <contactrom/rom/hdf5_io.hpp>
#include <contactrom/rom/offline.hpp>
#include <contactrom/rom/reduced_model_file.hpp>

namespace fs = std::filesystem;
using contactrom::InputError;
using contactrom::fom::Param;
using contactrom::rom::OnlineModel;
using contactrom::rom::OnlineResult;
using contactrom::test::run_command;
using contactrom::test::work_dir;

namespace {

const std::string exe = CONTACTROM_EXE;

std::shared_ptr<const contactrom::fom::Problem> hertz() {
  static std::shared_ptr<const contactrom::fom::Problem> p = contactrom::fom::make_problem("hertz");
  return p;
}

/// hertz with 10 training snapshots, also written to work_dir()/hertz10.h5.
const contactrom::rom::SnapshotDatabase& hertz_db() {
  static const contactrom::rom::SnapshotDatabase db = [] {
    auto d = contactrom::rom::generate_snapshots(*hertz(), 10);
    contactrom::rom::write_database(work_dir() + "/hertz10.h5", d);
    return d;
  }();
  return db;
}

/// Queries inside the range, between and at training parameters.
std::vector<Param> queries() {
  std::vector<Param> out;
  for (double d : {0.0123, 0.05, 0.1, 0.1789, 0.25, 0.3}) out.push_back(Param::Constant(1, d));
  return out;
}

/// max |v_i|, 0 for an empty v (a query that selects no column).
double max_abs(const Eigen::VectorXd& v) { return v.size() ? v.cwiseAbs().maxCoeff() : 0.0; }

/// The model's primal snapshots as format versions 1 and 2 stored them, measured from
/// the offset: u − u_off = (u − u_lift) − Σ_k φ_k (L̃_k − L_k), summed as the POD's
/// input is (bitwise the same numbers).
Eigen::MatrixXd from_offset(const contactrom::rom::ReducedModel& model) {
  Eigen::MatrixXd out = model.primal_snapshots();
  const contactrom::fom::Problem& problem = model.problem();
  for (Eigen::Index c = 0; c < out.cols(); ++c) {
    const Eigen::VectorXd phi = problem.load_coefficients(model.dictionary_parameters()[static_cast<size_t>(c)]);
    for (int k = 0; k < problem.num_load_terms(); ++k) {
      const Eigen::VectorXd d = model.offset_terms()[static_cast<size_t>(k)] - problem.lifting_terms()[static_cast<size_t>(k)];
      if (d.cwiseAbs().maxCoeff() > 0.0) out.col(c) -= phi(k) * d;
    }
  }
  return out;
}

/// As check_same_answers, to rounding (a file whose snapshots were converted).
void check_close_answers(const OnlineModel& a, const OnlineModel& b) {
  for (const Param& mu : queries()) {
    const OnlineResult x = a.solve(mu), y = b.solve(mu);
    BOOST_TEST(x.selected == y.selected);
    BOOST_TEST(x.status == y.status);
    BOOST_TEST(max_abs(x.coefficients - y.coefficients) <= 1e-10);
    BOOST_TEST((x.u - y.u).norm() <= 1e-10 * x.u.norm());
    BOOST_TEST((x.lambda - y.lambda).norm() <= 1e-10 * x.lambda.norm());
  }
}

void check_same_answers(const OnlineModel& a, const OnlineModel& b) {
  BOOST_TEST(a.model().primal_rank() == b.model().primal_rank());
  BOOST_TEST(a.model().dictionary_size() == b.model().dictionary_size());
  for (const Param& mu : queries()) {
    const OnlineResult x = a.solve(mu), y = b.solve(mu);
    BOOST_TEST(x.selected == y.selected);
    BOOST_TEST(x.iterations == y.iterations);
    BOOST_TEST(x.status == y.status);
    BOOST_TEST(max_abs(x.coefficients - y.coefficients) == 0.0);
    BOOST_TEST((x.u - y.u).cwiseAbs().maxCoeff() == 0.0);
    BOOST_TEST((x.lambda - y.lambda).cwiseAbs().maxCoeff() == 0.0);
  }
}

/// Overwrites element 0 of a double dataset of an HDF5 file; with `checksum`, also
/// stores the checksum of the new data (so that the reader's other checks see it).
void poke(const std::string& path, const char* dataset, double value, bool checksum = true) {
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  BOOST_REQUIRE(f >= 0);
  const hid_t d = H5Dopen2(f, dataset, H5P_DEFAULT);
  BOOST_REQUIRE(d >= 0);
  const hid_t space = H5Dget_space(d);
  const hsize_t start[2] = {0, 0}, count[2] = {1, 1};
  H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, count, nullptr);
  const hsize_t one[1] = {1};
  const hid_t mem = H5Screate_simple(1, one, nullptr);
  BOOST_REQUIRE(H5Dwrite(d, H5T_NATIVE_DOUBLE, mem, space, H5P_DEFAULT, &value) >= 0);
  if (checksum) {
    std::vector<double> all(static_cast<size_t>(H5Sget_simple_extent_npoints(space)));
    BOOST_REQUIRE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, all.data()) >= 0);
    const std::uint32_t sum = contactrom::rom::hdf5::data_checksum(all.data(), all.size() * sizeof(double));
    const hid_t attr = H5Aopen(d, contactrom::rom::hdf5::kChecksumAttribute, H5P_DEFAULT);
    BOOST_REQUIRE(attr >= 0);
    BOOST_REQUIRE(H5Awrite(attr, H5T_NATIVE_UINT32, &sum) >= 0);
    H5Aclose(attr);
  }
  H5Sclose(mem), H5Sclose(space), H5Dclose(d), H5Fclose(f);
}

std::string one_line_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

BOOST_AUTO_TEST_CASE(saved_model_answers_like_the_original_for_every_method) {
  contactrom::rom::ReducedModelOptions model_options;
  model_options.delta = 1e-8;
  for (const std::string method : {"greedy", "cpg", "convex-hull"}) {
    BOOST_TEST_CONTEXT("method " << method) {
      contactrom::rom::OnlineSolverOptions options;
      if (method == "greedy") options.extra["init"] = "empty";  // a non-default setting must survive the file
      const OnlineModel original(hertz(), hertz_db(), model_options, method, options);
      const std::string path = work_dir() + "/hertz10_" + method + ".h5";
      original.save(path);
      const OnlineModel loaded = OnlineModel::load(path);
      BOOST_TEST(loaded.method() == method);
      BOOST_TEST(contactrom::rom::options_to_map(method, loaded.options()) ==
                 contactrom::rom::options_to_map(method, original.options()));
      check_same_answers(original, loaded);
    }
  }
}

namespace {

bool has_attribute(const std::string& path, const char* name) {
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  BOOST_REQUIRE(f >= 0);
  const bool found = H5Aexists(f, name) > 0;
  H5Fclose(f);
  return found;
}

bool has_dataset(const std::string& path, const char* name) {
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  BOOST_REQUIRE(f >= 0);
  const bool found = H5Lexists(f, name, H5P_DEFAULT) > 0;
  H5Fclose(f);
  return found;
}

/// Turns a file written by save() back into the version-1 layout: primal snapshots
/// always (here: the convex hull's), no snapshot coordinates, format_version 1.
void make_version_1(const std::string& path) {
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  BOOST_REQUIRE(f >= 0);
  BOOST_REQUIRE(H5Ldelete(f, "snapshot_coordinates", H5P_DEFAULT) >= 0);
  const hid_t a = H5Aopen(f, "format_version", H5P_DEFAULT);
  const int one = 1;
  BOOST_REQUIRE(H5Awrite(a, H5T_NATIVE_INT, &one) >= 0);
  H5Aclose(a), H5Fclose(f);
}

/// Adds (or replaces) the m × n dataset /primal_snapshots (one column of `primal` per row).
void add_primal_snapshots(const std::string& path, const Eigen::MatrixXd& primal) {
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  BOOST_REQUIRE(f >= 0);
  if (H5Lexists(f, "primal_snapshots", H5P_DEFAULT) > 0) BOOST_REQUIRE(H5Ldelete(f, "primal_snapshots", H5P_DEFAULT) >= 0);
  const hsize_t dims[2] = {static_cast<hsize_t>(primal.cols()), static_cast<hsize_t>(primal.rows())};
  const hid_t space = H5Screate_simple(2, dims, nullptr);
  const hid_t d = H5Dcreate2(f, "primal_snapshots", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  BOOST_REQUIRE(H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, primal.data()) >= 0);
  // As contactrom writes every dataset: with the checksum of its data.
  contactrom::rom::hdf5::write_checksum_attribute(
      d, contactrom::rom::hdf5::data_checksum(primal.data(), static_cast<size_t>(primal.size()) * sizeof(double)),
      "dataset /primal_snapshots");
  H5Dclose(d), H5Sclose(space), H5Fclose(f);
}

}  // namespace

BOOST_AUTO_TEST_CASE(files_store_primal_snapshots_only_for_methods_that_combine_them) {
  const std::string greedy = work_dir() + "/hertz10_greedy_lean.h5", hull = work_dir() + "/hertz10_hull_lean.h5";
  const OnlineModel g(hertz(), hertz_db(), {}, "greedy"), h(hertz(), hertz_db(), {}, "convex-hull");
  g.save(greedy);
  h.save(hull);
  BOOST_TEST(!has_dataset(greedy, "primal_snapshots"));
  BOOST_TEST(has_dataset(hull, "primal_snapshots"));
  BOOST_TEST(!g.model().has_primal_snapshots());
  BOOST_TEST(fs::file_size(greedy) < fs::file_size(hull));
  // The coordinates are the projections of the training solutions measured from the
  // offset, Φᵀ(u − u_off(μ)), u from the database.
  const OnlineModel loaded = OnlineModel::load(greedy);
  const Eigen::MatrixXd& coords = loaded.model().snapshot_coordinates();
  Eigen::MatrixXd expected(coords.rows(), coords.cols());
  for (Eigen::Index c = 0; c < coords.cols(); ++c) {
    const Param mu = loaded.model().dictionary_parameters()[static_cast<size_t>(c)];
    const int j = loaded.model().dictionary_snapshots()[static_cast<size_t>(c)];
    const Eigen::VectorXd u = hertz_db().primal.col(j) + hertz()->lifting(mu);
    expected.col(c) = h.model().basis().transpose() * (u - h.model().offset(mu));
  }
  BOOST_TEST((coords - expected).cwiseAbs().maxCoeff() <= 1e-12 * expected.cwiseAbs().maxCoeff());
  check_same_answers(g, loaded);
  // A convex hull on a model without primal snapshots is refused, naming what is missing.
  contactrom::rom::ReducedModelOptions lean;
  lean.keep_primal_snapshots = false;
  const contactrom::rom::ReducedModel model(*hertz(), hertz_db(), lean);
  BOOST_TEST(one_line_error([&] { (void)contactrom::rom::make_online_solver("convex-hull", model); })
                 .find("primal training snapshots") != std::string::npos);
}

BOOST_AUTO_TEST_CASE(version_1_files_are_still_read) {
  // Version 1 stored the primal snapshots, measured from the offset (u − u_off), for
  // every method and no coordinates.
  const OnlineModel hull(hertz(), hertz_db(), {}, "convex-hull");
  const Eigen::MatrixXd primal = from_offset(hull.model());
  const Eigen::MatrixXd expected = hull.model().basis().transpose() * primal;
  for (const std::string method : {"greedy", "convex-hull"}) {
    BOOST_TEST_CONTEXT("method " << method) {
      const std::string path = work_dir() + "/hertz10_v1_" + method + ".h5";
      const OnlineModel original(hertz(), hertz_db(), {}, method);
      original.save(path);
      add_primal_snapshots(path, primal);
      make_version_1(path);
      const OnlineModel loaded = OnlineModel::load(path);
      BOOST_TEST(loaded.method() == method);
      BOOST_TEST(loaded.model().has_primal_snapshots() == (method == "convex-hull"));
      BOOST_TEST((loaded.model().snapshot_coordinates() - expected).cwiseAbs().maxCoeff() == 0.0);
      if (method == "greedy") check_same_answers(original, loaded);
      else check_close_answers(original, loaded);  // the snapshots back to u − u_lift: to rounding
    }
  }
}

namespace {

/// Makes a file as format version 2 wrote it: the offset kind in the attribute
/// `lifting` (version 3: `offset`).
void make_version_2(const std::string& path) {
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  BOOST_REQUIRE(f >= 0);
  const std::string kind = contactrom::rom::hdf5::read_string_attribute(f, "offset");
  BOOST_REQUIRE(H5Adelete(f, "offset") >= 0);
  contactrom::rom::hdf5::write_string_attribute(f, "lifting", kind);
  const hid_t a = H5Aopen(f, "format_version", H5P_DEFAULT);
  const int two = 2;
  BOOST_REQUIRE(H5Awrite(a, H5T_NATIVE_INT, &two) >= 0);
  H5Aclose(a), H5Fclose(f);
}

}  // namespace

BOOST_AUTO_TEST_CASE(version_2_files_are_still_read) {
  // Version 2 named the offset kind `lifting` and stored the convex hull's primal
  // snapshots measured from the offset (u − u_off); the model gets them back as the
  // database stores them (u − u_lift).
  using contactrom::rom::OffsetKind;
  for (const std::string method : {"greedy", "convex-hull"}) {
    for (const OffsetKind offset : {OffsetKind::Dirichlet, OffsetKind::Harmonic}) {
      BOOST_TEST_CONTEXT("method " << method << ", offset " << static_cast<int>(offset)) {
        contactrom::rom::ReducedModelOptions options;
        options.offset = offset;
        const OnlineModel original(hertz(), hertz_db(), options, method);
        const std::string path = work_dir() + "/hertz10_v2_" + method + std::to_string(static_cast<int>(offset)) + ".h5";
        original.save(path);
        if (method == "convex-hull") add_primal_snapshots(path, from_offset(original.model()));
        make_version_2(path);
        BOOST_TEST(!has_attribute(path, "offset"));
        const OnlineModel loaded = OnlineModel::load(path);
        BOOST_TEST((loaded.model().options().offset == offset));
        if (method == "greedy") {
          check_same_answers(original, loaded);
        } else {
          const Eigen::MatrixXd& stored = original.model().primal_snapshots();
          BOOST_TEST((loaded.model().primal_snapshots() - stored).norm() <= 1e-13 * stored.norm());
          check_close_answers(original, loaded);
        }
      }
    }
  }
}

BOOST_AUTO_TEST_CASE(loaded_model_reproduces_training_snapshots) {
  // The property the offline stage promises: at a training parameter the ROM gives
  // back (to the POD tolerance) the FOM snapshot it was built from.
  const std::string path = work_dir() + "/hertz10_greedy_train.h5";
  OnlineModel(hertz(), hertz_db(), {}, "greedy").save(path);
  const OnlineModel rom = OnlineModel::load(path);
  const auto& db = hertz_db();
  for (int j : {0, 4, 9}) {
    const OnlineResult res = rom.solve(db.parameter(j));
    BOOST_TEST(res.status == contactrom::Status::Success);
    const Eigen::VectorXd u = db.primal.col(j) + hertz()->lifting(db.parameter(j));
    BOOST_TEST((res.u - u).norm() <= 1e-3 * u.norm());
    BOOST_TEST((res.lambda - db.dual.col(j)).norm() <= 1e-3 * db.dual.col(j).norm());
  }
}

BOOST_AUTO_TEST_CASE(cli_reduce_then_query_matches_the_library) {
  (void)hertz_db();
  const std::string db = work_dir() + "/hertz10.h5", rom_path = work_dir() + "/cli_greedy.h5";
  const auto reduce = run_command(exe + " reduce --db " + db + " --method greedy --delta 1e-8 --out " + rom_path + " --json");
  BOOST_REQUIRE_MESSAGE(reduce.exit_code == 0, reduce.err);
  {
    std::ofstream csv(work_dir() + "/queries.csv");
    csv << "# hertz queries\nd\n0.0123\n0.1789\n0.3\n";
  }
  const std::string out = work_dir() + "/answers.csv";
  const auto query = run_command(exe + " query --rom " + rom_path + " --params " + work_dir() + "/queries.csv --out " +
                                 out + " --json");
  BOOST_REQUIRE_MESSAGE(query.exit_code == 0, query.err);
  const nlohmann::json j = nlohmann::json::parse(query.out);
  BOOST_REQUIRE(j["queries"].size() == 3u);
  const OnlineModel library(hertz(), hertz_db(), {}, "greedy");
  const std::vector<double> ds = {0.0123, 0.1789, 0.3};
  for (size_t i = 0; i < ds.size(); ++i) {
    const OnlineResult res = library.solve(Param::Constant(1, ds[i]));
    BOOST_TEST(j["queries"][i]["iterations"].get<int>() == res.iterations);
    BOOST_TEST(j["queries"][i]["contact_force"].get<double>() ==
               contactrom::fom::contact_force(*hertz(), res.lambda));
    std::vector<int> selected;
    for (int c : res.selected) selected.push_back(library.model().dictionary_snapshots()[static_cast<size_t>(c)]);
    BOOST_TEST(j["queries"][i]["selected"].get<std::vector<int>>() == selected);
  }
  BOOST_TEST(fs::exists(out));
  BOOST_TEST(contactrom::test::slurp(out).find("d,status,converged") == 0u);
}

BOOST_AUTO_TEST_CASE(damaged_or_wrong_files_are_refused_with_one_line) {
  const std::string good = work_dir() + "/hertz10_good.h5";
  OnlineModel(hertz(), hertz_db(), {}, "greedy").save(good);

  BOOST_TEST(one_line_error([] { OnlineModel::load(work_dir() + "/missing.h5"); }).find("not found") !=
             std::string::npos);
  // A snapshot database is not a reduced model.
  const std::string db_error = one_line_error([] { OnlineModel::load(work_dir() + "/hertz10.h5"); });
  BOOST_TEST(db_error.find("not a contactrom reduced model") != std::string::npos, db_error);
  // Truncated.
  const std::string cut = work_dir() + "/cut.h5";
  fs::copy_file(good, cut, fs::copy_options::overwrite_existing);
  fs::resize_file(cut, fs::file_size(good) / 2);
  const std::string cut_error = one_line_error([&] { OnlineModel::load(cut); });
  BOOST_TEST(cut_error.find(cut) != std::string::npos, cut_error);
  // A non-finite number in the reduced operators.
  const std::string nan = work_dir() + "/nan.h5";
  fs::copy_file(good, nan, fs::copy_options::overwrite_existing);
  poke(nan, "reduced/stiffness_0", std::nan(""));
  const std::string nan_error = one_line_error([&] { OnlineModel::load(nan); });
  BOOST_TEST(nan_error.find("non-finite") != std::string::npos, nan_error);
  // A dictionary parameter outside the problem's range.
  const std::string out_of_range = work_dir() + "/range.h5";
  fs::copy_file(good, out_of_range, fs::copy_options::overwrite_existing);
  poke(out_of_range, "dictionary_parameters", 7.0);
  const std::string range_error = one_line_error([&] { OnlineModel::load(out_of_range); });
  BOOST_TEST(range_error.find("dictionary_parameters") != std::string::npos, range_error);
  for (const std::string* e : {&db_error, &cut_error, &nan_error, &range_error})
    BOOST_TEST(e->find('\n') == std::string::npos);

  // The CLI: exit 2, one line, no output file.
  const std::string out = work_dir() + "/never.csv";
  const auto r = run_command(exe + " query --rom " + nan + " --param 0.1 --out " + out);
  BOOST_TEST(r.exit_code == 2);
  BOOST_TEST(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  BOOST_TEST(!fs::exists(out));
  const auto bad_param = run_command(exe + " query --rom " + good + " --param 0.5");
  BOOST_TEST(bad_param.exit_code == 2);
  BOOST_TEST(bad_param.err.find("0.5") != std::string::npos, bad_param.err);
}

BOOST_AUTO_TEST_CASE(every_stored_list_and_number_is_checked) {
  const std::string good = work_dir() + "/hertz10_lists.h5";
  OnlineModel(hertz(), hertz_db(), {}, "greedy").save(good);
  // NaN or Inf in the singular values or the surface rows of the basis.
  for (const char* dataset : {"singular_values", "surface_basis"})
    for (double bad : {std::nan(""), HUGE_VAL}) {
      const std::string damaged = work_dir() + "/damaged.h5";
      fs::copy_file(good, damaged, fs::copy_options::overwrite_existing);
      poke(damaged, dataset, bad);
      const std::string e = one_line_error([&] { OnlineModel::load(damaged); });
      BOOST_TEST(e.find(std::string("/") + dataset) != std::string::npos, e);
    }
  // The node list of the Dirichlet curve of the load without its last node: another
  // problem (that node no longer pushed), which the stored fingerprint must refuse.
  const std::string emptied = work_dir() + "/emptied.h5";
  fs::copy_file(good, emptied, fs::copy_options::overwrite_existing);
  const auto py = run_command(
      "/usr/bin/python3 -c \"import h5py, numpy; f = h5py.File('" + emptied + "', 'a'); "
      "names = [n.decode() for n in f['mesh/curve_names'][()]]; k = 'mesh/curve_%d_nodes' % names.index('top_load'); "
      "data = f[k][()][:-1]; del f[k]; f.create_dataset(k, data=data); "
      "import sys; sys.path.insert(0, '" + std::string(CONTACTROM_SOURCE_DIR) + "/fuzz'); "
      "from hdf5_checksum import lookup3; f[k].attrs.create('checksum_lookup3', lookup3(data.tobytes()), dtype='<u4')\"");
  BOOST_REQUIRE_MESSAGE(py.exit_code == 0, "needs /usr/bin/python3 with h5py: " << py.err);
  const std::string e = one_line_error([&] { OnlineModel::load(emptied); });
  BOOST_TEST(e.find("fingerprint") != std::string::npos, e);
  // A column's snapshot index edited (its checksum with it) out of database order.
  const std::string reordered = work_dir() + "/reordered.h5";
  fs::copy_file(good, reordered, fs::copy_options::overwrite_existing);
  const auto edit = run_command(
      "/usr/bin/python3 -c \"import h5py, numpy; f = h5py.File('" + reordered + "', 'a'); k = 'dictionary_snapshots'; "
      "data = f[k][()]; data[0] = 1000000; dtype = f[k].dtype; del f[k]; f.create_dataset(k, data=data.astype(dtype)); "
      "import sys; sys.path.insert(0, '" + std::string(CONTACTROM_SOURCE_DIR) + "/fuzz'); "
      "from hdf5_checksum import lookup3; f[k].attrs.create('checksum_lookup3', lookup3(f[k][()].tobytes()), dtype='<u4')\"");
  BOOST_REQUIRE_MESSAGE(edit.exit_code == 0, edit.err);
  const std::string order = one_line_error([&] { OnlineModel::load(reordered); });
  BOOST_TEST(order.find("/dictionary_snapshots is not increasing") != std::string::npos, order);
  // A number changed without its checksum: the file is damaged.
  const std::string flipped = work_dir() + "/flipped.h5";
  fs::copy_file(good, flipped, fs::copy_options::overwrite_existing);
  poke(flipped, "dictionary", 0.5, false);
  const std::string f = one_line_error([&] { OnlineModel::load(flipped); });
  BOOST_TEST(f.find("/dictionary fails its checksum") != std::string::npos, f);
}

BOOST_AUTO_TEST_CASE(parameter_csv_is_checked_row_by_row) {
  const std::string path = work_dir() + "/params.csv";
  {
    std::ofstream f(path);
    f << "d\n0.1\n# comment\n\n0.2\n";
  }
  const auto params = contactrom::rom::read_parameter_csv(path, *hertz());
  BOOST_REQUIRE(params.size() == 2u);
  BOOST_TEST(params[1](0) == 0.2);
  {
    std::ofstream f(path);
    f << "d\n0.1\n# comment\n\n0.4\n";
  }
  // The line of the value, counting the header, comments and blank lines.
  const std::string e = one_line_error([&] { contactrom::rom::read_parameter_csv(path, *hertz()); });
  BOOST_TEST(e.find("line 5: parameter d = 0.4 is outside") != std::string::npos, e);
  {
    std::ofstream f(path);
    f << "0.1,0.2\n";
  }
  const std::string e2 = one_line_error([&] { contactrom::rom::read_parameter_csv(path, *hertz()); });
  BOOST_TEST(e2.find("2 values per line") != std::string::npos, e2);
}
