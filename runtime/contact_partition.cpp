#include "runtime/contact_partition.hpp"

#include <zoltan.h>

#include <algorithm>
#include <map>

#include "kernels/error.hpp"
#include "runtime/allgather_list.hpp"

namespace shatter {

std::vector<int> align_parts(int parts, std::vector<std::array<long, 3>> overlap) {
  std::sort(overlap.begin(), overlap.end());
  std::vector<std::array<long, 3>> summed;
  for (const auto& o : overlap)
    if (!summed.empty() && summed.back()[0] == o[0] && summed.back()[1] == o[1])
      summed.back()[2] += o[2];
    else
      summed.push_back(o);
  std::stable_sort(summed.begin(), summed.end(), [](const auto& a, const auto& b) { return a[2] > b[2]; });
  std::vector<int> rank_of(parts, -1);
  std::vector<char> taken(parts, 0);
  for (const auto& [part, home, count] : summed)
    if (rank_of[part] < 0 && !taken[home]) rank_of[part] = static_cast<int>(home), taken[home] = 1;
  for (int p = 0, r = 0; p < parts; ++p) {
    if (rank_of[p] >= 0) continue;
    while (taken[r]) ++r;
    rank_of[p] = r, taken[r] = 1;
  }
  return rank_of;
}

ContactPartition::ContactPartition(MPI_Comm comm) : comm_(comm) {
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
  float version = 0;
  SHATTER_REQUIRE(Zoltan_Initialize(0, nullptr, &version) == ZOLTAN_OK, "Zoltan_Initialize failed");
  zz_ = Zoltan_Create(comm);
  SHATTER_REQUIRE(zz_, "Zoltan_Create failed");
  for (const auto& [key, value] : {std::pair{"DEBUG_LEVEL", "0"}, {"LB_METHOD", "RCB"}, {"NUM_GID_ENTRIES", "4"}, {"NUM_LID_ENTRIES", "1"},
                                   {"OBJ_WEIGHT_DIM", "2"}, {"RETURN_LISTS", "EXPORT"},
                                   {"RCB_REUSE", "0"}, {"KEEP_CUTS", "0"}, {"REMAP", "0"}, {"IMBALANCE_TOL", "1.02"}})
    Zoltan_Set_Param(zz_, key, value);
  Zoltan_Set_Num_Obj_Fn(
      zz_, [](void* data, int* ierr) -> int {
        *ierr = ZOLTAN_OK;
        return static_cast<int>(static_cast<ContactPartition*>(data)->points_.size());
      },
      this);
  Zoltan_Set_Obj_List_Fn(
      zz_,
      [](void* data, int, int, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids, int wdim, float* weights, int* ierr) {
        const auto* self = static_cast<ContactPartition*>(data);
        for (size_t k = 0; k < self->points_.size(); ++k) {
          for (int w = 0; w < kNameWords; ++w)
            gids[kNameWords * k + w] = static_cast<ZOLTAN_ID_TYPE>(self->names_[kNameWords * k + w]);
          lids[k] = static_cast<ZOLTAN_ID_TYPE>(k);
          for (int w = 0; w < wdim; ++w) weights[k * wdim + w] = self->weights_[2 * k + w];
        }
        *ierr = ZOLTAN_OK;
      },
      this);
  Zoltan_Set_Num_Geom_Fn(
      zz_, [](void*, int* ierr) -> int {
        *ierr = ZOLTAN_OK;
        return 3;
      },
      this);
  Zoltan_Set_Geom_Multi_Fn(
      zz_,
      [](void* data, int, int, int n, ZOLTAN_ID_PTR, ZOLTAN_ID_PTR lids, int dim, double* xyz, int* ierr) {
        const auto* self = static_cast<ContactPartition*>(data);
        for (int k = 0; k < n; ++k)
          for (int c = 0; c < dim; ++c) xyz[k * dim + c] = self->points_[lids[k]][c];
        *ierr = ZOLTAN_OK;
      },
      this);
}

ContactPartition::~ContactPartition() { Zoltan_Destroy(&zz_); }

std::vector<int> ContactPartition::partition(std::span<const Index> names, std::span<const Vec3> points,
                                             std::span<const float> weights, std::span<const int> homes) {
  SHATTER_REQUIRE(names.size() == kNameWords * points.size() && 2 * points.size() == weights.size() &&
                      homes.size() == points.size(),
                  "ContactPartition: " << names.size() << " name words, " << points.size() << " points, "
                                       << weights.size() << " weights, " << homes.size() << " homes");
  names_ = names;
  points_ = points;
  weights_ = weights;
  int changes = 0, gid_entries = 0, lid_entries = 0, n_import = 0, n_export = 0;
  ZOLTAN_ID_PTR import_gids = nullptr, import_lids = nullptr, export_gids = nullptr, export_lids = nullptr;
  int *import_procs = nullptr, *import_parts = nullptr, *export_procs = nullptr, *export_parts = nullptr;
  const int rc = Zoltan_LB_Partition(zz_, &changes, &gid_entries, &lid_entries, &n_import, &import_gids, &import_lids,
                                     &import_procs, &import_parts, &n_export, &export_gids, &export_lids,
                                     &export_procs, &export_parts);
  std::vector<int> to(points.size(), rank_);
  if (rc == ZOLTAN_OK)
    for (int k = 0; k < n_export; ++k) to[export_lids[k]] = export_parts[k];
  Zoltan_LB_Free_Part(&import_gids, &import_lids, &import_procs, &import_parts);
  Zoltan_LB_Free_Part(&export_gids, &export_lids, &export_procs, &export_parts);
  // Every rank gets the same return code: Zoltan's calls are collective.
  SHATTER_REQUIRE(rc == ZOLTAN_OK, "Zoltan_LB_Partition (RCB) failed with code " << rc);
  // Zoltan numbers the parts; each goes to the rank where most of its objects are at home.
  std::map<std::pair<int, int>, long> mine;
  for (size_t k = 0; k < to.size(); ++k) ++mine[{to[k], homes[k]}];
  std::vector<long> words;
  for (const auto& [key, count] : mine) words.insert(words.end(), {key.first, key.second, count});
  const std::vector<long> all = allgather_list(std::span<const long>(words), MPI_LONG, comm_);
  std::vector<std::array<long, 3>> overlap(all.size() / 3);
  for (size_t k = 0; k < overlap.size(); ++k) overlap[k] = {all[3 * k], all[3 * k + 1], all[3 * k + 2]};
  const std::vector<int> rank_of = align_parts(size_, std::move(overlap));
  for (int& r : to) r = rank_of[r];
  return to;
}

}  // namespace shatter
