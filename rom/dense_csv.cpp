#include <contactrom/rom/dense_csv.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <istream>
#include <vector>

#include <contactrom/core/errors.hpp>
#include <contactrom/core/format.hpp>
#include <contactrom/core/input_file.hpp>
#include <contactrom/fom/input_values.hpp>

namespace contactrom::rom {

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::string trim(const std::string& text) {
  std::size_t begin = 0;
  std::size_t end = text.size();
  while (begin < end && is_blank(text[begin])) ++begin;
  while (end > begin && is_blank(text[end - 1])) --end;
  return text.substr(begin, end - begin);
}

/// Parses one field; throws naming the file, line and column on anything that is
/// not a finite number.
double parse_value(const std::string& field, const std::string& name, std::size_t line, std::size_t column) {
  const std::string text = trim(field);
  const std::string where = name + ": line " + std::to_string(line) + ", column " + std::to_string(column) + ": ";
  if (text.empty()) throw InputError(where + "empty value, expected a number");
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || end == text.c_str()) {
    throw InputError(where + quoted(text) + " is not a number");
  }
  if (!std::isfinite(value)) {  // nan, inf, or overflow (strtod returns HUGE_VAL)
    throw InputError(where + quoted(text) + " is not a finite number");
  }
  return value;
}

}  // namespace

Eigen::MatrixXd read_dense_csv(std::istream& in, const std::string& name, std::vector<std::size_t>* row_lines) {
  if (row_lines) row_lines->clear();
  std::vector<double> values;
  std::size_t columns = 0;
  std::size_t rows = 0;
  std::size_t first_data_line = 0;
  std::string line;
  std::size_t line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line_number == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);  // a UTF-8 byte-order mark
    const std::string content = trim(line);
    if (content.empty() || content[0] == '#') continue;
    std::size_t count = 0;
    if (content.find(',') == std::string::npos) {
      // No comma: values separated by blanks (numpy.savetxt's default).
      std::size_t start = 0;
      while (start < content.size()) {
        std::size_t end = start;
        while (end < content.size() && !is_blank(content[end])) ++end;
        values.push_back(parse_value(content.substr(start, end - start), name, line_number, ++count));
        start = end;
        while (start < content.size() && is_blank(content[start])) ++start;
      }
    } else {
      std::size_t start = 0;
      while (true) {
        const std::size_t comma = line.find(',', start);
        const std::string field = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        values.push_back(parse_value(field, name, line_number, ++count));
        if (comma == std::string::npos) break;
        start = comma + 1;
      }
    }
    if (rows == 0) {
      columns = count;
      first_data_line = line_number;
    } else if (count != columns) {
      throw InputError(name + ": line " + std::to_string(line_number) + ": " + std::to_string(count) +
                       " values, expected " + std::to_string(columns) + " (as on line " +
                       std::to_string(first_data_line) + ")");
    }
    ++rows;
    if (row_lines) row_lines->push_back(line_number);
  }
  if (in.bad()) throw InputError(name + ": read error");
  if (rows == 0) throw InputError(name + ": no values (nothing but blank lines, comments or a header), expected at least one row of numbers");
  Eigen::MatrixXd matrix(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(columns));
  for (std::size_t i = 0; i < rows; ++i) {
    for (std::size_t j = 0; j < columns; ++j) {
      matrix(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = values[i * columns + j];
    }
  }
  return matrix;
}

namespace {
/// Largest CSV file read (1 GiB): the values of a dictionary of 10^8 entries.
constexpr std::uintmax_t kMaxCsvBytes = std::uintmax_t{1} << 30;
}  // namespace

Eigen::MatrixXd read_dense_csv(const std::string& path) {
  check_input_file(path, "CSV file", kMaxCsvBytes);
  std::ifstream in(path);
  if (!in) throw InputError("cannot open " + quoted(path, 200) + ": no such file or not readable");
  return read_dense_csv(in, path);
}

Eigen::VectorXd read_vector_csv(const std::string& path) {
  const Eigen::MatrixXd matrix = read_dense_csv(path);
  if (matrix.cols() == 1) return matrix.col(0);
  if (matrix.rows() == 1) return matrix.row(0).transpose();
  throw InputError(path + ": " + std::to_string(matrix.rows()) + "x" + std::to_string(matrix.cols()) +
                   " values, expected one column or one row");
}

}  // namespace contactrom::rom
