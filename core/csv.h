// Small helpers for the CSV files users hand in (measurements, motion curves): trimming, splitting a line,
// and reading a number with an error that names the file, line, column and text.
#pragma once

#include <string>
#include <vector>

namespace dipper {

/// The text without leading and trailing blanks, tabs and carriage returns.
std::string trim(const std::string& text);
/// The comma-separated cells of a line, each trimmed (a trailing comma gives a last empty cell).
std::vector<std::string> split_csv_line(const std::string& line);
/// The whole text as a finite number; otherwise an InputError "where: column 'c' has 'text'; expected a
/// finite number".
double parse_csv_number(const std::string& text, const std::string& where, const std::string& column);

}  // namespace dipper
