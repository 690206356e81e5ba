#include "runtime/report.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "kernels/error.hpp"

namespace shatter {

CsvWriter::CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns, bool append)
    : out_(path, append ? std::ios::app : std::ios::trunc), path_(path) {
  SHATTER_REQUIRE(out_, "cannot " << (append ? "open " : "create ") << path.string());
  out_ << std::setprecision(17);
  if (append) return;
  for (size_t i = 0; i < columns.size(); ++i) out_ << (i ? "," : "") << columns[i];
  out_ << '\n';
}

void CsvWriter::sep() {
  if (!first_) out_ << ',';
  first_ = false;
}
CsvWriter& CsvWriter::operator<<(double v) {
  sep();
  // %.17g without the stream's locale and formatting state (a tenth of the time).
  char text[32];
  const auto [end, error] = std::to_chars(text, text + sizeof text, v, std::chars_format::general, 17);
  SHATTER_ASSERT(error == std::errc());
  out_.write(text, end - text);
  return *this;
}
CsvWriter& CsvWriter::operator<<(long v) {
  sep();
  char text[24];
  const auto [end, error] = std::to_chars(text, text + sizeof text, v);
  SHATTER_ASSERT(error == std::errc());
  out_.write(text, end - text);
  return *this;
}
CsvWriter& CsvWriter::operator<<(const std::string& s) {
  sep();
  out_ << s;
  return *this;
}
void CsvWriter::end_row() {
  out_ << '\n';
  first_ = true;
}
void CsvWriter::flush() {
  out_.flush();
  SHATTER_REQUIRE(out_, "cannot write " << path_.string());
}

namespace {
std::string json_string(const std::string& s) {
  std::ostringstream os;
  os << '"';
  for (char c : s) {
    if (c == '"' || c == '\\') os << '\\' << c;
    else if (static_cast<unsigned char>(c) < 0x20) os << "\\u" << std::hex << std::setw(4) << std::setfill('0') << int(c);
    else os << c;
  }
  os << '"';
  return os.str();
}
}  // namespace

void JsonObject::add(const std::string& key, const std::string& value) { items_.emplace_back(key, json_string(value)); }
void JsonObject::add(const std::string& key, double value) {
  std::ostringstream os;
  os << std::setprecision(17);
  if (std::isfinite(value)) os << value;
  else os << "null";
  items_.emplace_back(key, os.str());
}
void JsonObject::add(const std::string& key, long value) { items_.emplace_back(key, std::to_string(value)); }
void JsonObject::add(const std::string& key, const std::vector<long>& values) {
  std::string list = "[";
  for (size_t i = 0; i < values.size(); ++i) list += (i ? ", " : "") + std::to_string(values[i]);
  items_.emplace_back(key, list + "]");
}

void JsonObject::write(const std::filesystem::path& path) const {
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp);
    SHATTER_REQUIRE(out, "cannot create " << tmp.string());
    out << "{\n";
    for (size_t i = 0; i < items_.size(); ++i)
      out << "  " << json_string(items_[i].first) << ": " << items_[i].second << (i + 1 < items_.size() ? ",\n" : "\n");
    out << "}\n";
    SHATTER_REQUIRE(out, "cannot write " << tmp.string());
  }
  std::filesystem::rename(tmp, path);
}

Progress::Progress(double end_time, bool quiet)
    : end_time_(end_time), quiet_(quiet), tty_(isatty(STDERR_FILENO)), start_(std::chrono::steady_clock::now()),
      last_print_(start_) {}

void Progress::update(long step, double time, double dt, double energy_error, bool force) {
  if (quiet_) return;
  const auto now = std::chrono::steady_clock::now();
  const double frac = std::min(1.0, time / end_time_);
  const int decile = static_cast<int>(std::floor(frac * 10 + 1e-9));
  if (tty_) {
    if (!force && now - last_print_ < std::chrono::milliseconds(100)) return;
  } else {
    if (!force && decile == last_decile_) return;
  }
  last_decile_ = decile;
  last_print_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double eta = frac > 0 ? elapsed * (1 - frac) / frac : 0.0;
  char line[200];
  std::snprintf(line, sizeof line, "step %ld  t %.4e s  dt %.3e s  %5.1f %%  ETA %.0f s  energy error %+.2e", step,
                time, dt, 100 * frac, eta, energy_error);
  if (tty_) std::fprintf(stderr, "\r%s\033[K", line);
  else std::fprintf(stderr, "%s\n", line);
  printed_ = true;
}

void Progress::finish() {
  if (!quiet_ && tty_ && printed_) std::fprintf(stderr, "\n");
}

long peak_memory_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss * 1024L;
}

}  // namespace shatter
