#pragma once
/// \file problem_record_io.hpp
/// \brief The HDF5 reading and writing of a ProblemRecord (rom/problem_record.hpp),
/// shared by the snapshot database and the reduced-model file. A private header of
/// contactrom::rom: it includes <hdf5.h>, which the installed package does not provide.
#include <hdf5.h>

#include <contactrom/rom/problem_record.hpp>

namespace contactrom::rom {

/// \brief Writes the attributes `problem`, `mesh_fingerprint`, `param_names` on `file`
/// and the datasets /problem_file, /contact/points, /contact/weights, /lifting, /mesh/….
/// \throws hdf5::Failure
void write_problem_record(hid_t file, hid_t dcpl, const ProblemRecord& record);

/// \brief Reads what write_problem_record wrote, checking the contact datasets
/// against `num_constraints` rows, the lifting against `num_dofs`, and every mesh
/// index against the node count. \throws hdf5::Failure or hdf5::Refused
ProblemRecord read_problem_record(hid_t file, hsize_t num_constraints, hsize_t num_dofs);

}  // namespace contactrom::rom
