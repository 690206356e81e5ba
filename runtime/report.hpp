#pragma once
// Plain-text outputs: CSV tables (history.csv, bodies.csv, fragments.csv),
// summary.json, and the progress line on stderr.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace shatter {

/// A CSV file with a header row; numbers written with 17 significant digits
/// (as printf's %.17g) so that a row read back is the same double. Rows reach
/// the file at flush(), which a writer calls once per output step (history.csv
/// and bodies.csv: one flush for the step's rows, not one system call per row).
class CsvWriter {
 public:
  /// append: keep the file's rows (a restart; its header must be `columns`)
  /// and add the new rows after them.
  CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns, bool append = false);
  /// Start a row; add values with operator<<; end with end_row().
  CsvWriter& operator<<(double v);
  CsvWriter& operator<<(long v);
  CsvWriter& operator<<(int v) { return *this << static_cast<long>(v); }
  CsvWriter& operator<<(const std::string& s);
  void end_row();
  /// The rows so far into the file (a killed run keeps them); exits on a write error.
  void flush();

 private:
  void sep();
  std::ofstream out_;
  std::filesystem::path path_;
  bool first_ = true;
};

/// A flat JSON object writer for summary.json (string, number and integer values, lists of integers).
class JsonObject {
 public:
  void add(const std::string& key, const std::string& value);
  void add(const std::string& key, double value);
  void add(const std::string& key, long value);
  void add(const std::string& key, int value) { add(key, static_cast<long>(value)); }
  void add(const std::string& key, const std::vector<long>& values);
  /// Write atomically (temporary file + rename).
  void write(const std::filesystem::path& path) const;

 private:
  std::vector<std::pair<std::string, std::string>> items_;
};

/// Progress on stderr: step, time, dt, percent, ETA, energy error; refreshed in
/// place on a terminal (at most 10 times a second), a line every 10 % otherwise,
/// nothing when quiet.
class Progress {
 public:
  Progress(double end_time, bool quiet);
  void update(long step, double time, double dt, double energy_error, bool force = false);
  void finish();

 private:
  double end_time_;
  bool quiet_, tty_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_print_;
  bool printed_ = false;
};

/// Peak resident memory of this process, bytes.
long peak_memory_bytes();

}  // namespace shatter
