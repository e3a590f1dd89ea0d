// The tables a printf bench prints, kept so that it can also write them as
// JSON (`--json FILE`), which scripts/results/render.py reads.
//
//   BenchTables out("joint_bench", TakeJsonFlag(&argc, argv));
//   Table& t = out.Start("Depth (GT person pixels)", {"method", "AbsRel"});
//   t.Row({"full", Cell("%.4f", abs_rel)});   // printed as it comes
//   out.Write();                              // <FILE>, when --json was given
//
// Start prints "\n<title>\n" (unless print_title is false), then the header
// "| a | b |" and "|---|---|"; Row prints "| x | y |". Record keeps a table
// that the bench prints in its own format (its rows are not printed). The JSON is
// {"bench": ..., "tables": [{"title", "columns", "rows": [[cells as printed]]}]}.
#pragma once

#include <deque>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace u4d::bench {

// printf into a string: a cell exactly as the bench printed it.
std::string Cell(const char* format, ...) __attribute__((format(printf, 1, 2)));

// Removes "--json FILE" from argv (argc shrinks); FILE, or "" if absent (exits 2
// when FILE is missing). Write exits 1 when it cannot write FILE.
std::string TakeJsonFlag(int* argc, char** argv);

class Table {
 public:
  Table(std::string title, std::vector<std::string> columns, bool printed);
  void PrintHead(bool print_title) const;
  void Row(std::vector<std::string> cells);  // kept for the JSON (and printed now)
  nlohmann::json Json() const;

 private:
  std::string title_;
  std::vector<std::string> columns_;
  std::vector<std::vector<std::string>> rows_;
  bool printed_;
};

class BenchTables {
 public:
  BenchTables(std::string bench, std::string json_path);
  Table& Start(std::string title, std::vector<std::string> columns, bool print_title = true);
  Table& Record(std::string title, std::vector<std::string> columns);
  void Write() const;  // the JSON file, when a path was given

 private:
  std::string bench_, path_;
  std::deque<Table> tables_;  // references stay valid as tables are added
};

}  // namespace u4d::bench
