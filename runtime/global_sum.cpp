#include "runtime/global_sum.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "kernels/error.hpp"

namespace shatter {

namespace {

// The message, in 64-bit words: the number of maxima M, then each accumulator's
// kDigits digits (normalized) and its special (a double's bits), then the M maxima.
// It is one element of its own contiguous type, so the operation sees it whole.
constexpr int kWords = ExactSum::kDigits + 1;

size_t message_words(size_t accumulators, size_t maxima) { return 1 + accumulators * kWords + maxima; }

std::vector<std::int64_t> pack(std::span<ExactSum> acc, std::span<const long> most) {
  std::vector<std::int64_t> words(message_words(acc.size(), most.size()));
  words[0] = static_cast<std::int64_t>(most.size());
  for (size_t k = 0; k < acc.size(); ++k) {
    acc[k].normalize();
    const auto d = acc[k].digits();
    std::int64_t* at = words.data() + 1 + k * kWords;
    std::copy(d.begin(), d.end(), at);
    at[ExactSum::kDigits] = std::bit_cast<std::int64_t>(acc[k].special());
  }
  std::copy(most.begin(), most.end(), words.end() - static_cast<std::ptrdiff_t>(most.size()));
  return words;
}

void unpack(const std::vector<std::int64_t>& words, std::span<ExactSum> acc, std::span<long> most) {
  for (size_t k = 0; k < acc.size(); ++k) {
    const std::int64_t* at = words.data() + 1 + k * kWords;
    const auto d = acc[k].digits();
    std::copy(at, at + ExactSum::kDigits, d.begin());
    acc[k].set_special(std::bit_cast<double>(at[ExactSum::kDigits]));
    acc[k].normalize();
  }
  std::copy(words.end() - static_cast<std::ptrdiff_t>(most.size()), words.end(), most.begin());
}

// Digits add as integers (normalized digits add without overflow), specials as
// doubles (only 0, infinities and NaN: any order gives the same), maxima as maxima.
void combine(void* in, void* inout, int* len, MPI_Datatype* type) {
  int bytes = 0;
  MPI_Type_size(*type, &bytes);
  const auto words = static_cast<size_t>(bytes) / sizeof(std::int64_t);
  for (int e = 0; e < *len; ++e) {
    const std::int64_t* a = static_cast<const std::int64_t*>(in) + e * words;
    std::int64_t* b = static_cast<std::int64_t*>(inout) + e * words;
    const auto most = static_cast<size_t>(a[0]);
    const size_t count = (words - 1 - most) / kWords;
    for (size_t k = 0; k < count; ++k) {
      const std::int64_t* x = a + 1 + k * kWords;
      std::int64_t* y = b + 1 + k * kWords;
      for (int i = 0; i < ExactSum::kDigits; ++i) y[i] += x[i];
      y[ExactSum::kDigits] = std::bit_cast<std::int64_t>(std::bit_cast<double>(x[ExactSum::kDigits]) +
                                                         std::bit_cast<double>(y[ExactSum::kDigits]));
    }
    for (size_t i = words - most; i < words; ++i) b[i] = std::max(a[i], b[i]);
  }
}

// A message of doubles, one element: minima (a NaN wins, whatever the order, so every
// rank gets the same), then a (key, index) pair compared lexicographically (the index
// is an integer below 2^53, exact as a double).
void min_then_least(void* in, void* inout, int* len, MPI_Datatype* type) {
  int bytes = 0;
  MPI_Type_size(*type, &bytes);
  const auto n = static_cast<size_t>(bytes) / sizeof(double);
  for (int e = 0; e < *len; ++e) {
    const double* a = static_cast<const double*>(in) + e * n;
    double* b = static_cast<double*>(inout) + e * n;
    for (size_t i = 0; i + 2 < n; ++i) b[i] = std::isnan(a[i]) || a[i] < b[i] ? a[i] : b[i];
    if (a[n - 2] < b[n - 2] || (a[n - 2] == b[n - 2] && a[n - 1] < b[n - 1])) b[n - 2] = a[n - 2], b[n - 1] = a[n - 1];
  }
}

/// A commutative operation made once `function`'s static instance is first used.
template <MPI_User_function* function>
MPI_Op op() {
  static const MPI_Op made = [] {
    MPI_Op o;
    MPI_Op_create(function, 1, &o);
    return o;
  }();
  return made;
}

/// A message's type: its `count` words of `word` as one element, so that an operation
/// sees it whole.
struct MessageType {
  MessageType(size_t count, MPI_Datatype word) {
    MPI_Type_contiguous(static_cast<int>(count), word, &type);
    MPI_Type_commit(&type);
  }
  ~MessageType() { MPI_Type_free(&type); }
  MessageType(const MessageType&) = delete;
  MessageType& operator=(const MessageType&) = delete;
  MPI_Datatype type;
};

}  // namespace

std::size_t allreduce_bytes(std::size_t accumulators, std::size_t maxima) {
  return sizeof(std::int64_t) * message_words(accumulators, maxima);
}

void allreduce(std::span<ExactSum> acc, MPI_Comm comm, std::span<long> most) {
  static_assert(sizeof(long) == sizeof(std::int64_t));
  std::vector<std::int64_t> words = pack(acc, most);
  const MessageType message(words.size(), MPI_INT64_T);
  MPI_Allreduce(MPI_IN_PLACE, words.data(), 1, message.type, op<&combine>(), comm);
  unpack(words, acc, most);
}

void reduce_to_root(std::span<ExactSum> acc, MPI_Comm comm, int root) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::vector<std::int64_t> words = pack(acc, {}), out(rank == root ? words.size() : 0);
  const MessageType message(words.size(), MPI_INT64_T);
  MPI_Reduce(words.data(), out.data(), 1, message.type, op<&combine>(), root, comm);
  if (rank == root) unpack(out, acc, {});
}

void allreduce_min(std::span<double> values, std::pair<double, long>& least, MPI_Comm comm) {
  SHATTER_REQUIRE(std::abs(least.second) < (1L << 53), "allreduce_min: index " << least.second << " beyond 2^53");
  std::vector<double> message(values.begin(), values.end());
  message.push_back(least.first);
  message.push_back(static_cast<double>(least.second));
  const MessageType type(message.size(), MPI_DOUBLE);
  MPI_Allreduce(MPI_IN_PLACE, message.data(), 1, type.type, op<&min_then_least>(), comm);
  std::copy(message.begin(), message.end() - 2, values.begin());
  least = {message[message.size() - 2], static_cast<long>(message.back())};
}

}  // namespace shatter
