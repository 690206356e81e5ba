#include "runtime/global_sum.hpp"

#include <algorithm>
#include <vector>

namespace shatter {

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
