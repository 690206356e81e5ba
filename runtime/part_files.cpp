#include "runtime/part_files.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <regex>
#include <set>
#include <string>

#include "kernels/error.hpp"
#include "runtime/decomposition.hpp"
#include "runtime/fnv1a.hpp"
#include "runtime/model_part.hpp"
#include "runtime/scene_keys.hpp"

namespace shatter {
namespace {

constexpr std::array<char, 16> kMagic{"shatter parts"};
constexpr std::uint64_t kVersion = 4;

/// A file written through a running hash; the hash goes last.
class HashedWriter {
 public:
  explicit HashedWriter(const std::filesystem::path& path) : out_(path, std::ios::binary | std::ios::trunc) {}
  void put(const void* data, std::uint64_t bytes) {
    hash_ = fnv1a(data, bytes, hash_);
    out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  }
  void word(std::uint64_t w) { put(&w, sizeof w); }
  /// Writes the hash and closes; false when any write failed.
  bool finish() {
    const std::uint64_t h = hash_;
    out_.write(reinterpret_cast<const char*>(&h), sizeof h);
    out_.close();
    return !out_.fail();
  }

 private:
  std::ofstream out_;
  std::uint64_t hash_ = fnv1a(nullptr, 0);
};

/// The rank counts of the part files in `dir`, ascending ("part-<r>-of-<R>.bin").
std::set<int> rank_counts_in(const std::filesystem::path& dir) {
  std::set<int> counts;
  std::error_code ec;
  const std::regex name(R"(part-[0-9]+-of-([0-9]+)\.bin)");
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    std::smatch m;
    const std::string file = entry.path().filename().string();
    if (std::regex_match(file, m, name)) counts.insert(std::stoi(m[1].str()));
  }
  return counts;
}

/// This rank's part from its file; throws InputError naming the file.
void read_own(Model& model, const std::filesystem::path& dir, int rank, int ranks) {
  const std::filesystem::path path = part_file(dir, rank, ranks);
  const std::string where = path.string() + ": ";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    std::string found;
    for (const int r : rank_counts_in(dir)) found += (found.empty() ? "" : ", ") + std::to_string(r);
    throw InputError(where + "no such part file (" +
                     (found.empty() ? "the folder holds no part files" : "the folder holds parts for " + found + " ranks") +
                     "); expected the parts of `shatter partition SCENE --ranks " + std::to_string(ranks) + "`");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  std::ifstream in(path, std::ios::binary);
  if (ec || !in) throw InputError(where + "cannot be read: " + std::strerror(errno));
  constexpr std::uintmax_t kHead = kMagic.size() + 4 * sizeof(std::uint64_t), kTail = sizeof(std::uint64_t);
  if (size < kHead + kTail) throw InputError(where + "is " + std::to_string(size) + " bytes, too short for a part file");
  // Pass 1: the hash of everything before the last word, by chunks.
  const std::uintmax_t body = size - kTail;
  std::vector<char> chunk(1 << 20);
  std::uint64_t h = fnv1a(nullptr, 0), stored = 0;
  for (std::uintmax_t at = 0; at < body;) {
    const auto n = static_cast<std::streamsize>(std::min<std::uintmax_t>(chunk.size(), body - at));
    if (!in.read(chunk.data(), n)) throw InputError(where + "cannot be read (truncated while reading?)");
    h = fnv1a(chunk.data(), static_cast<std::size_t>(n), h);
    at += static_cast<std::uintmax_t>(n);
  }
  in.read(reinterpret_cast<char*>(&stored), sizeof stored);
  // Pass 2: the header, then the part.
  in.seekg(0);
  std::uintmax_t left = body;
  auto get = [&](void* data, std::uint64_t bytes) {
    in.read(static_cast<char*>(data), static_cast<std::streamsize>(bytes));
    left -= bytes;
  };
  std::array<char, kMagic.size()> magic{};
  get(magic.data(), magic.size());
  if (magic != kMagic) throw InputError(where + "is not a shatter part file (expected one written by `shatter partition`)");
  if (stored != h) throw InputError(where + "fails its hash check (a damaged or truncated part file); partition the scene again");
  std::uint64_t head[4];
  get(head, sizeof head);
  if (head[0] != kVersion)
    throw InputError(where + "is a part file of version " + std::to_string(head[0]) + "; expected version " +
                     std::to_string(kVersion) + " (partition the scene again)");
  if (head[1] != static_cast<std::uint64_t>(rank) || head[2] != static_cast<std::uint64_t>(ranks))
    throw InputError(where + "holds part " + std::to_string(head[1]) + " of " + std::to_string(head[2]) +
                     "; expected part " + std::to_string(rank) + " of " + std::to_string(ranks));
  if (head[3] > left) throw InputError(where + "is not a complete part file");
  std::string physics(head[3], '\0');
  get(physics.data(), physics.size());
  const KeyDifference d = first_difference(physics, physics_keys(model.scene));
  if (!d.key.empty())
    throw InputError(where + d.key + " is " + d.a + " in the scene the parts were cut from and " + d.b + " in " +
                     model.scene.file + "; expected the same physics (partition the scene again)");
  if (!get_part(model, left, get) || left != 0 || !in)
    throw InputError(where + "is not a complete part file (its arrays do not fill it)");
}

}  // namespace

std::filesystem::path part_file(const std::filesystem::path& dir, int rank, int ranks) {
  return dir / ("part-" + std::to_string(rank) + "-of-" + std::to_string(ranks) + ".bin");
}

std::vector<std::uintmax_t> write_part_files(const Model& whole, int ranks, const std::filesystem::path& dir) {
  const Scene& scene = whole.scene;
  if (scene.has_shells())
    throw InputError(scene.file + ": shells hold the whole model on every rank (docs/parallel.md \"Shells on ranks\"); "
                                  "expected a scene without shells, or a run that meshes at start-up");
  if (ranks < 2) throw InputError("--ranks " + std::to_string(ranks) + ": expected at least 2 ranks (one rank needs no parts)");
  check_ranks(whole, ranks);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir.string() + ": cannot make the folder: " + ec.message());
  const std::string physics = physics_keys(scene);
  std::vector<std::uintmax_t> sizes(ranks, 0);
  cut_parts(whole, ranks, [&](int r, Model&& part) {
    const std::filesystem::path path = part_file(dir, r, ranks), tmp = path.string() + ".tmp";
    HashedWriter w(tmp);
    w.put(kMagic.data(), kMagic.size());
    for (const std::uint64_t word : {kVersion, static_cast<std::uint64_t>(r), static_cast<std::uint64_t>(ranks),
                                     static_cast<std::uint64_t>(physics.size())})
      w.word(word);
    w.put(physics.data(), physics.size());
    put_part(part, [&](const void* data, std::uint64_t bytes) { w.put(data, bytes); });
    const int err = errno;
    if (!w.finish()) {
      std::filesystem::remove(tmp, ec);
      throw Error(tmp.string() + ": cannot write the part file: " + std::strerror(err));
    }
    std::filesystem::rename(tmp, path, ec);
    if (ec) throw Error(tmp.string() + ": cannot rename it to " + path.string() + ": " + ec.message());
    sizes[r] = std::filesystem::file_size(path);
  });
  return sizes;
}

void read_part_file(Model& model, const std::filesystem::path& dir, MPI_Comm comm) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  std::string error;
  try {
    read_own(model, dir, rank, ranks);
  } catch (const InputError& e) {
    error = e.what();
  }
  // Every rank throws the lowest failing rank's message.
  int first = error.empty() ? ranks : rank;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == ranks) return;
  int length = static_cast<int>(error.size());
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  error.resize(length);
  MPI_Bcast(error.data(), length, MPI_CHAR, first, comm);
  throw InputError(error);
}

}  // namespace shatter
