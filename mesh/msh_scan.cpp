#include "mesh/msh_scan.hpp"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "kernels/error.hpp"

namespace shatter {
namespace {

/// The walk of scan_msh_elements over one file: sections are found as Gmsh
/// finds them (a line starting with '$', names matched by prefix), $Elements
/// sections are parsed, every other one skipped: by its layout when it is
/// binary ($Nodes; $Entities of 4.1), else up to its "$End" line.
class MshScan {
 public:
  MshScan(const std::string& path, const std::string& where, const std::string& named)
      : path_(named.empty() ? path : named), where_(where), in_(path, std::ios::binary) {
    if (!in_) fail("cannot be opened");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<std::uint64_t>(in_.tellg());
    in_.seekg(0);
  }

  std::vector<MshElementType> run() {
    std::string line;
    if (!next_line(line) || line.rfind("$MeshFormat", 0) != 0)
      fail(
          "does not begin with $MeshFormat; expected a Gmsh .msh file of format 2.2 or 4.1 (ASCII "
          "or binary)");
    format();
    while (next_line(line)) {
      if (line.empty() || line[0] != '$' || line.rfind("$End", 0) == 0) continue;
      if (line.rfind("$Elements", 0) == 0) {
        v41_ ? elements_v41() : elements_v2();
      } else if (binary_ && line.rfind("$Nodes", 0) == 0) {
        v41_ ? skip_nodes_v41() : skip_nodes_v2();
      } else if (binary_ && v41_ && line.rfind("$Entities", 0) == 0) {
        skip_entities_v41();
      } else {
        while (next_line(line) && line.rfind("$End", 0) != 0) {
        }
      }
    }
    return types_;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(where_ + ": '" + path_ + "' " + why);
  }
  [[noreturn]] void cut(const char* section) const {
    fail(std::string("is cut short or malformed in its ") + section +
         " section; expected a Gmsh .msh file of format 2.2 or 4.1 (ASCII or binary)");
  }

  bool next_line(std::string& line) {
    if (!std::getline(in_, line)) return false;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  }

  // "$MeshFormat": version, file type, data size; binary files then hold
  // the integer 1, in the byte order of the machine that wrote them.
  void format() {
    std::string line, version;
    int file_type = -1, data_size = 0;
    if (!next_line(line) || !(std::istringstream(line) >> version >> file_type >> data_size))
      cut("$MeshFormat");
    double v = 0;
    const auto [end, ec] = std::from_chars(version.data(), version.data() + version.size(), v);
    if (ec != std::errc() || end != version.data() + version.size() ||
        !(v == 4.1 || (v >= 2 && v < 3)))
      fail("is of .msh format " + version + "; expected format 2.2 or 4.1 (ASCII or binary)");
    if ((file_type != 0 && file_type != 1) || data_size != 8) cut("$MeshFormat");
    v41_ = v == 4.1;
    binary_ = file_type == 1;
    if (!binary_) return;
    const auto one = get<std::int32_t>("$MeshFormat");
    if (one != 1) {
      swap_ = true;
      if (swapped(one) != 1) cut("$MeshFormat");
    }
  }

  template <class T>
  static T swapped(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    std::reverse(b, b + sizeof(T));
    std::memcpy(&v, b, sizeof(T));
    return v;
  }

  template <class T>
  T get(const char* section) {
    T v;
    if (!in_.read(reinterpret_cast<char*>(&v), sizeof(T))) cut(section);
    return swap_ ? swapped(v) : v;
  }

  /// A count in a binary file (int or size_t), refused when negative.
  template <class T>
  std::uint64_t get_count(const char* section) {
    const T v = get<T>(section);
    if (v < 0) cut(section);
    return static_cast<std::uint64_t>(v);
  }

  /// Skips `items` of `bytes` each, refused when they run past the end.
  void skip(std::uint64_t items, std::uint64_t bytes, const char* section) {
    if (!in_) cut(section);
    const std::uint64_t left = size_ - static_cast<std::uint64_t>(in_.tellg());
    if (bytes > 0 && items > left / bytes) cut(section);
    in_.seekg(static_cast<std::streamoff>(items * bytes), std::ios::cur);
  }

  /// The next whitespace-separated number of an ASCII section.
  std::uint64_t number(const char* section) {
    std::string token;
    std::uint64_t v = 0;
    if (!(in_ >> token)) cut(section);
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
    if (ec != std::errc() || end != token.data() + token.size()) cut(section);
    return v;
  }

  /// The nodes of element `tag`, refused unless each is a tag Gmsh 4.8 can
  /// look up: it takes node tags as int (GModel::getMeshVertexByTag), and a
  /// tag at or beyond 2^31, or negative, read memory before its table (a
  /// segfault, or a node made of whatever was there, which Gmsh then wrote
  /// into its .msh copy: mesh/mesh_file.cpp).
  void check_node(long long node, std::uint64_t tag) const {
    if (node < 1 || static_cast<std::uint64_t>(node) > kMaxNodeTag) bad_node(std::to_string(node), tag);
  }
  [[noreturn]] void bad_node(const std::string& node, std::uint64_t tag) const {
    fail("holds element " + std::to_string(tag) + " naming node " + node + "; expected node tags from 1 to " +
         std::to_string(kMaxNodeTag));
  }
  static constexpr std::uint64_t kMaxNodeTag = 2147483647;  // 2^31 - 1

  /// The `n` node tags of ASCII element `tag`.
  void node_tokens(std::uint64_t n, std::uint64_t tag, const char* section) {
    std::string token;
    for (std::uint64_t i = 0; i < n; ++i) {
      if (!(in_ >> token)) cut(section);
      long long node = 0;
      const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), node);
      if (ec == std::errc::result_out_of_range) bad_node(token, tag);
      if (ec != std::errc() || end != token.data() + token.size()) cut(section);
      check_node(node, tag);
    }
  }

  /// `n` binary elements of one block, each its tag, `ntags` tags and
  /// `nodes` node tags, all of type T; the first one's tag `first` read.
  template <class T>
  void node_records(std::uint64_t n, std::uint64_t ntags, std::uint64_t nodes, std::uint64_t first,
                    const char* section) {
    const std::uint64_t per = 1 + ntags + nodes;  // words per element
    const std::streamoff start = in_.tellg();
    skip(1, sizeof(T) * (per - 1), section);  // refused when past the end, before reading
    skip(n - 1, sizeof(T) * per, section);
    in_.seekg(start);
    std::uint64_t words = n * per - 1, at = 1, tag = first;  // at: the word's place in its element
    std::vector<T> buffer(std::min<std::uint64_t>(words, 1 << 16));
    while (words > 0) {
      const std::uint64_t k = std::min<std::uint64_t>(words, buffer.size());
      if (!in_.read(reinterpret_cast<char*>(buffer.data()), static_cast<std::streamsize>(sizeof(T) * k))) cut(section);
      for (std::uint64_t i = 0; i < k; ++i, at = (at + 1) % per) {
        const T v = swap_ ? swapped(buffer[i]) : buffer[i];
        if (at == 0)
          tag = static_cast<std::uint64_t>(v);
        else if (at > ntags && (v < T(1) || static_cast<std::uint64_t>(v) > kMaxNodeTag))
          bad_node(std::to_string(v), tag);
      }
      words -= k;
    }
  }

  void skip_tokens(std::uint64_t n, const char* section) {
    std::string token;
    for (std::uint64_t i = 0; i < n; ++i)
      if (!(in_ >> token)) cut(section);
  }

  /// Nodes per element of Gmsh element `type`: the types of the Gmsh
  /// reference manual's MSH list (1-31, 92, 93). Gmsh's own table
  /// (getElementProperties) builds each type's nodal basis, and for prisms
  /// Gmsh 4.8 frees memory with the wrong operator (found by fuzz_msh).
  int nodes_of(std::uint64_t type, std::uint64_t tag) const {
    static constexpr int kNodes[32] = {0, 2,  3,  4,  4, 8,  6,  5,  3,  6,  9, 10, 27, 18, 14, 1,
                                       8, 20, 15, 13, 9, 10, 12, 15, 15, 21, 4, 5,  6,  20, 35, 56};
    const int nodes = type < 32 ? kNodes[type] : type == 92 ? 64 : type == 93 ? 125 : 0;
    if (nodes == 0)
      fail("holds element " + std::to_string(tag) + " of type " + std::to_string(type) +
           ", which is not a Gmsh element type; expected the types of the Gmsh reference "
           "manual (4: 4-node tetrahedron, 11: 10-node)");
    return nodes;
  }

  /// Tetrahedra of orders 1 to 5 (the manual's types 4, 11, 29, 30, 31).
  static bool tetrahedron(std::uint64_t type) {
    return type == 4 || type == 11 || type == 29 || type == 30 || type == 31;
  }

  void record(std::uint64_t type, std::uint64_t count, std::uint64_t first_tag) {
    if (count == 0) return;
    auto it = std::find_if(types_.begin(), types_.end(),
                           [&](const MshElementType& t) { return t.type == int(type); });
    if (it == types_.end()) {
      MshElementType t;
      t.type = static_cast<int>(type);
      t.nodes = nodes_of(type, first_tag);
      t.tetrahedron = tetrahedron(type);
      t.first_tag = first_tag;
      it = types_.insert(types_.end(), t);
    }
    it->count += count;
  }

  // Format 2: a count line, then per element "tag type ntags tags... nodes...";
  // binary: blocks of (type, count, ntags) ints, then per element the tag,
  // tags and nodes as ints.
  void elements_v2() {
    const char* s = "$Elements";
    std::string line;
    std::uint64_t count = 0;
    if (!next_line(line)) cut(s);
    {
      std::istringstream is(line);
      long long c = -1;
      if (!(is >> c) || c < 0) cut(s);
      count = static_cast<std::uint64_t>(c);
    }
    for (std::uint64_t done = 0; done < count;) {
      if (binary_) {
        const std::uint64_t type = get_count<std::int32_t>(s), n = get_count<std::int32_t>(s),
                            ntags = get_count<std::int32_t>(s);
        if (n == 0) continue;
        const auto tag = get_count<std::int32_t>(s);
        const int nodes = nodes_of(type, tag);
        node_records<std::int32_t>(n, ntags, static_cast<std::uint64_t>(nodes), tag, s);
        record(type, n, tag);
        done += n;
      } else {
        const std::uint64_t tag = number(s), type = number(s), ntags = number(s);
        skip_tokens(ntags, s);
        node_tokens(nodes_of(type, tag), tag, s);
        record(type, 1, tag);
        ++done;
      }
    }
  }

  // Format 4.1: blocks, sizes and tags std::size_t, dimensions, entity tags
  // and types int; per block "dim entity type count", then per element the
  // tag and its nodes.
  void elements_v41() {
    const char* s = "$Elements";
    const std::uint64_t blocks = binary_ ? get_count<std::uint64_t>(s) : number(s);
    if (binary_)
      skip(3, 8, s);
    else
      skip_tokens(3, s);
    for (std::uint64_t b = 0; b < blocks; ++b) {
      std::uint64_t type = 0, n = 0;
      if (binary_) {
        skip(2, 4, s);
        type = get_count<std::int32_t>(s);
        n = get<std::uint64_t>(s);
      } else {
        skip_tokens(2, s);
        type = number(s);
        n = number(s);
      }
      if (n == 0) continue;
      const std::uint64_t tag = binary_ ? get<std::uint64_t>(s) : number(s);
      const std::uint64_t nodes = nodes_of(type, tag);
      if (binary_) {
        node_records<std::uint64_t>(n, 0, nodes, tag, s);
      } else {
        node_tokens(nodes, tag, s);
        for (std::uint64_t i = 1; i < n; ++i) node_tokens(nodes, number(s), s);
      }
      record(type, n, tag);
    }
  }

  // Binary $Nodes, format 2: a count line, then per node an int tag and three doubles.
  void skip_nodes_v2() {
    std::string line;
    long long count = -1;
    if (!next_line(line) || !(std::istringstream(line) >> count) || count < 0) cut("$Nodes");
    skip(static_cast<std::uint64_t>(count), 4 + 3 * 8, "$Nodes");
  }

  // Binary $Nodes, format 4.1: blocks (entity dim, tag, parametric as int,
  // count as size_t), the block's tags, then its coordinates: x y z and, when
  // parametric, one more per dimension of the entity.
  void skip_nodes_v41() {
    const char* s = "$Nodes";
    const std::uint64_t blocks = get<std::uint64_t>(s);
    skip(3, 8, s);
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const std::uint64_t dim = get_count<std::int32_t>(s);
      skip(1, 4, s);
      const std::uint64_t parametric = get_count<std::int32_t>(s), n = get<std::uint64_t>(s);
      if (dim > 3 || parametric > 1) cut(s);
      skip(n, 8, s);
      skip(n, 8 * (3 + parametric * dim), s);
    }
  }

  // Binary $Entities, format 4.1: counts of points, curves, surfaces and
  // volumes (size_t); a point is a tag, x y z and its physical tags; the
  // others a tag, a bounding box, physical tags and bounding entities.
  void skip_entities_v41() {
    const char* s = "$Entities";
    std::uint64_t counts[4];
    for (auto& c : counts) c = get<std::uint64_t>(s);
    for (int dim = 0; dim < 4; ++dim)
      for (std::uint64_t e = 0; e < counts[dim]; ++e) {
        skip(1, 4 + (dim == 0 ? 3 : 6) * 8, s);
        skip(get<std::uint64_t>(s), 4, s);
        if (dim > 0) skip(get<std::uint64_t>(s), 4, s);
      }
  }

  std::string path_, where_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
  bool v41_ = false, binary_ = false, swap_ = false;
  std::vector<MshElementType> types_;
};

}  // namespace

std::vector<MshElementType> scan_msh_elements(const std::string& path, const std::string& where,
                                              const std::string& named) {
  return MshScan(path, where, named).run();
}

}  // namespace shatter
