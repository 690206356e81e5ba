#include "runtime/contact_partition.hpp"

#include <zoltan.h>

#include "kernels/error.hpp"

namespace shatter {

ContactPartition::ContactPartition(MPI_Comm comm) : comm_(comm) {
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
  float version = 0;
  SHATTER_REQUIRE(Zoltan_Initialize(0, nullptr, &version) == ZOLTAN_OK, "Zoltan_Initialize failed");
  zz_ = Zoltan_Create(comm);
  SHATTER_REQUIRE(zz_, "Zoltan_Create failed");
  for (const auto& [key, value] : {std::pair{"DEBUG_LEVEL", "0"}, {"LB_METHOD", "RCB"}, {"NUM_GID_ENTRIES", "4"}, {"NUM_LID_ENTRIES", "1"},
                                   {"OBJ_WEIGHT_DIM", "2"}, {"RETURN_LISTS", "EXPORT"},
                                   {"RCB_REUSE", "0"}, {"KEEP_CUTS", "0"}, {"IMBALANCE_TOL", "1.02"}})
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
                                             std::span<const float> weights) {
  SHATTER_REQUIRE(names.size() == kNameWords * points.size() && 2 * points.size() == weights.size(),
                  "ContactPartition: " << names.size() << " name words, " << points.size() << " points, "
                                       << weights.size() << " weights");
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
  return to;
}

}  // namespace shatter
