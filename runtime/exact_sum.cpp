#include "runtime/exact_sum.hpp"

#include <cmath>
#include <vector>

namespace shatter {

void ExactSum::add(double x) {
  if (x == 0) return;
  if (!std::isfinite(x)) {
    special_ += x;
    return;
  }
  int e = 0;
  const double m = std::frexp(x, &e);  // x = m 2^e, 0.5 <= |m| < 1
  const std::int64_t mantissa = static_cast<std::int64_t>(std::ldexp(m, 53));  // exact, |mantissa| < 2^53
  const int p = e - 53 + kBias;                                                // x = mantissa 2^(p - kBias)
  const int i = p >> 5;
  const unsigned __int128 u = static_cast<unsigned __int128>(mantissa < 0 ? -mantissa : mantissa) << (p & 31);
  const std::int64_t d0 = static_cast<std::int64_t>(u & 0xffffffffu), d1 = static_cast<std::int64_t>((u >> 32) & 0xffffffffu),
                     d2 = static_cast<std::int64_t>(u >> 64);
  if (mantissa < 0) {
    digits_[i] -= d0, digits_[i + 1] -= d1, digits_[i + 2] -= d2;
  } else {
    digits_[i] += d0, digits_[i + 1] += d1, digits_[i + 2] += d2;
  }
  if (++pending_ == (1 << 30)) normalize();
}

void ExactSum::normalize() {
  for (int i = 0; i + 1 < kDigits; ++i) {
    const std::int64_t carry = digits_[i] >> 32;  // floor division by 2^32
    digits_[i] -= carry * (std::int64_t{1} << 32);
    digits_[i + 1] += carry;
  }
  pending_ = 0;
}

ExactSum& ExactSum::operator+=(const ExactSum& o) {
  ExactSum b = o;
  b.normalize();
  normalize();
  for (int i = 0; i < kDigits; ++i) digits_[i] += b.digits_[i];
  special_ += b.special_;
  normalize();
  return *this;
}

double ExactSum::value() const {
  if (special_ != 0 || std::isnan(special_)) return special_;
  ExactSum a = *this;
  a.normalize();
  const bool negative = a.digits_[kDigits - 1] < 0;
  if (negative) {
    for (std::int64_t& d : a.digits_) d = -d;
    a.normalize();
  }
  int top = kDigits - 1;
  while (top >= 0 && a.digits_[top] == 0) --top;
  if (top < 0) return 0.0;
  // The top four digits (>= 97 significant bits), smallest first: non-negative
  // terms, each rounding by at most half an ulp of the partial sum.
  double r = 0;
  for (int i = std::max(0, top - 3); i <= top; ++i)
    r += std::ldexp(static_cast<double>(a.digits_[i]), 32 * i - kBias);
  return negative ? -r : r;
}

namespace {

/// The accumulators' digits (normalized) and specials, packed for MPI.
void pack(std::span<ExactSum> acc, std::vector<std::int64_t>& digits, std::vector<double>& specials) {
  digits.resize(acc.size() * ExactSum::kDigits);
  specials.resize(acc.size());
  for (size_t k = 0; k < acc.size(); ++k) {
    acc[k].normalize();
    const auto d = acc[k].digits();
    std::copy(d.begin(), d.end(), digits.begin() + k * ExactSum::kDigits);
    specials[k] = acc[k].special();
  }
}

void unpack(std::span<ExactSum> acc, const std::vector<std::int64_t>& digits, const std::vector<double>& specials) {
  for (size_t k = 0; k < acc.size(); ++k) {
    const auto d = acc[k].digits();
    std::copy(digits.begin() + k * ExactSum::kDigits, digits.begin() + (k + 1) * ExactSum::kDigits, d.begin());
    acc[k].set_special(specials[k]);
    acc[k].normalize();
  }
}

}  // namespace

void allreduce(std::span<ExactSum> acc, MPI_Comm comm) {
  std::vector<std::int64_t> digits;
  std::vector<double> specials;
  pack(acc, digits, specials);
  MPI_Allreduce(MPI_IN_PLACE, digits.data(), static_cast<int>(digits.size()), MPI_INT64_T, MPI_SUM, comm);
  MPI_Allreduce(MPI_IN_PLACE, specials.data(), static_cast<int>(specials.size()), MPI_DOUBLE, MPI_SUM, comm);
  unpack(acc, digits, specials);
}

void reduce_to_root(std::span<ExactSum> acc, MPI_Comm comm, int root) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::vector<std::int64_t> digits, out;
  std::vector<double> specials, out_specials;
  pack(acc, digits, specials);
  if (rank == root) out.resize(digits.size()), out_specials.resize(specials.size());
  MPI_Reduce(digits.data(), out.data(), static_cast<int>(digits.size()), MPI_INT64_T, MPI_SUM, root, comm);
  MPI_Reduce(specials.data(), out_specials.data(), static_cast<int>(specials.size()), MPI_DOUBLE, MPI_SUM, root,
             comm);
  if (rank == root) unpack(acc, out, out_specials);
}

}  // namespace shatter
