#include "bench_table.h"

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <utility>

namespace u4d::bench {
namespace {

void PrintCells(const std::vector<std::string>& cells) {
  std::string line = "|";
  for (const std::string& c : cells) line += " " + c + " |";
  std::printf("%s\n", line.c_str());
}

// A usage or output error: the message on stderr, then exit.
[[noreturn]] void Fail(const std::string& message, int status) {
  std::fprintf(stderr, "%s\n", message.c_str());
  std::exit(status);
}

}  // namespace

std::string Cell(const char* format, ...) {
  va_list args, copy;
  va_start(args, format);
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string s(n > 0 ? n : 0, '\0');
  if (n > 0) std::vsnprintf(s.data(), s.size() + 1, format, args);
  va_end(args);
  return s;
}

std::string TakeJsonFlag(int* argc, char** argv) {
  std::string path;
  int out = 1;
  for (int i = 1; i < *argc; ++i) {
    if (std::strcmp(argv[i], "--json") != 0) {
      argv[out++] = argv[i];
      continue;
    }
    if (i + 1 >= *argc) Fail(std::string(argv[0]) + ": --json needs a file name", 2);
    path = argv[++i];
  }
  *argc = out;
  argv[out] = nullptr;
  return path;
}

Table::Table(std::string title, std::vector<std::string> columns, bool printed)
    : title_(std::move(title)), columns_(std::move(columns)), printed_(printed) {}

void Table::PrintHead(bool print_title) const {
  if (print_title) std::printf("\n%s\n", title_.c_str());
  PrintCells(columns_);
  std::string rule = "|";
  for (size_t i = 0; i < columns_.size(); ++i) rule += "---|";
  std::printf("%s\n", rule.c_str());
}

void Table::Row(std::vector<std::string> cells) {
  if (printed_) PrintCells(cells);
  rows_.push_back(std::move(cells));
}

nlohmann::json Table::Json() const {
  return {{"title", title_}, {"columns", columns_}, {"rows", rows_}};
}

BenchTables::BenchTables(std::string bench, std::string json_path)
    : bench_(std::move(bench)), path_(std::move(json_path)) {}

Table& BenchTables::Start(std::string title, std::vector<std::string> columns, bool print_title) {
  tables_.emplace_back(std::move(title), std::move(columns), true);
  tables_.back().PrintHead(print_title);
  return tables_.back();
}

Table& BenchTables::Record(std::string title, std::vector<std::string> columns) {
  return tables_.emplace_back(std::move(title), std::move(columns), false);
}

void BenchTables::Write() const {
  if (path_.empty()) return;
  nlohmann::json tables = nlohmann::json::array();
  for (const Table& t : tables_) tables.push_back(t.Json());
  std::ofstream f(path_);
  f << nlohmann::json{{"bench", bench_}, {"tables", tables}}.dump(1) << "\n";
  if (!f) Fail(bench_ + ": cannot write " + path_, 1);
}

}  // namespace u4d::bench
