#pragma once
/// \file dense_csv.hpp
/// \brief Reading dense matrices and vectors from CSV files (the input format of
/// `contactrom sparse`).
///
/// Format: one matrix row per line, values separated by commas (optional spaces or
/// tabs around each value) or, on a line without a comma, by spaces or tabs (the
/// default of numpy.savetxt); `\n` or `\r\n` line ends. Lines that are empty (or only
/// blanks) and lines whose first non-blank character is `#` are skipped. Every value
/// must be a finite decimal number (as accepted by `std::strtod`, e.g. `1`, `-2.5`,
/// `3e-7`); `nan`, `inf`, empty fields and trailing text are rejected.
///
/// Malformed input throws contactrom::InputError with a one-line message naming the
/// file, the line and the column (1-based), the value found and what was expected.
#include <Eigen/Dense>
#include <iosfwd>
#include <string>
#include <vector>

namespace contactrom::rom {

/// \brief Reads a dense matrix from a CSV file.
/// \param path file to read.
/// \returns the matrix; its rows are the data lines of the file.
/// \throws InputError if the file cannot be opened, holds no value, has a row with a
///         number of values different from the first data row, or a value that is
///         not a finite number.
Eigen::MatrixXd read_dense_csv(const std::string& path);

/// \brief Parses CSV text from a stream; `name` is used in error messages in place
/// of a file name. `row_lines` (optional) receives the line number of every row.
Eigen::MatrixXd read_dense_csv(std::istream& in, const std::string& name, std::vector<std::size_t>* row_lines = nullptr);

/// \brief Reads a vector from a CSV file holding either one column (one value per
/// line) or one row.
/// \throws InputError as read_dense_csv(), or if the file holds a matrix with more
///         than one row and more than one column.
Eigen::VectorXd read_vector_csv(const std::string& path);

}  // namespace contactrom::rom
