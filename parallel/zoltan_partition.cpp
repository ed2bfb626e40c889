#include "parallel/zoltan_partition.hpp"

#include <zoltan.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <string>

#include "core/error.hpp"

namespace fdem {

namespace {

static_assert(sizeof(ZOLTAN_ID_TYPE) * 2 >= sizeof(GlobalId), "a gid fits two Zoltan id entries");
constexpr int gid_entries =
    (sizeof(GlobalId) + sizeof(ZOLTAN_ID_TYPE) - 1) / sizeof(ZOLTAN_ID_TYPE);

// Zoltan query callbacks over the caller's points.
int count_points(void* data, int* error) {
  *error = ZOLTAN_OK;
  return static_cast<int>(static_cast<const std::vector<PartitionPoint>*>(data)->size());
}

void list_points(void* data, int n_gid, int n_lid, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids,
                 int weight_dim, float* weights, int* error) {
  const auto& points = *static_cast<const std::vector<PartitionPoint>*>(data);
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::memcpy(gids + i * n_gid, &points[i].gid, sizeof(GlobalId));
    if (n_lid > 0) lids[i * n_lid] = static_cast<ZOLTAN_ID_TYPE>(i);
    if (weight_dim > 0) weights[i] = static_cast<float>(points[i].weight);
  }
  *error = ZOLTAN_OK;
}

int dimension(void*, int* error) {
  *error = ZOLTAN_OK;
  return 3;
}

void coordinates(void* data, int, int n_lid, int count, ZOLTAN_ID_PTR, ZOLTAN_ID_PTR lids, int,
                 double* x, int* error) {
  const auto& points = *static_cast<const std::vector<PartitionPoint>*>(data);
  for (int i = 0; i < count; ++i)
    std::memcpy(x + 3 * i, points[lids[i * n_lid]].x, sizeof(double) * 3);
  *error = ZOLTAN_OK;
}

void check(int status, const char* call) {
  FDEM_VERIFY(status == ZOLTAN_OK || status == ZOLTAN_WARN,
              std::string("Zoltan ") + call + " failed");
}

// Overlap of one rank's points with one new part (weight), gathered to every rank.
struct PartOverlap {
  std::int32_t rank;
  std::int32_t part;
  double weight;
};

// Renames the parts so that each stays, as far as a greedy matching finds, on the rank that
// already holds most of its weight. Zoltan's bisections number parts by their recursion, not by
// who holds what, so without this a cut that barely moved can swap two ranks' whole contents (and
// the checkpoint's gid blocks, which follow the start-up order, with them). Each rank
// contributes a few overlaps (the parts its points go to): O(P) numbers in all, never O(N).
void keep_parts_on_their_ranks(std::vector<std::int32_t>& parts,
                               const std::vector<PartitionPoint>& points,
                               const Communicator& comm) {
  std::map<std::int32_t, double> local;
  for (std::size_t i = 0; i < parts.size(); ++i) local[parts[i]] += points[i].weight + 1e-30;
  std::vector<PartOverlap> mine;
  for (const auto& [part, weight] : local) mine.push_back({comm.rank(), part, weight});
  std::vector<PartOverlap> all = comm.allgatherv(mine);
  // Heaviest overlaps first; ties broken by (rank, part) so that every rank decides alike.
  std::sort(all.begin(), all.end(), [](const PartOverlap& a, const PartOverlap& b) {
    if (a.weight != b.weight) return a.weight > b.weight;
    return a.rank != b.rank ? a.rank < b.rank : a.part < b.part;
  });
  const int ranks = comm.size();
  std::vector<std::int32_t> rank_of_part(static_cast<std::size_t>(ranks), -1);
  std::vector<char> rank_taken(static_cast<std::size_t>(ranks), 0);
  for (const PartOverlap& o : all) {
    if (rank_of_part[o.part] >= 0 || rank_taken[o.rank]) continue;
    rank_of_part[o.part] = o.rank;
    rank_taken[o.rank] = 1;
  }
  int next_free = 0;  // parts that no rank holds any of go to the ranks left, in order
  for (std::int32_t& r : rank_of_part) {
    if (r >= 0) continue;
    while (rank_taken[next_free]) ++next_free;
    r = next_free;
    rank_taken[next_free] = 1;
  }
  for (std::int32_t& part : parts) part = rank_of_part[part];
}

}  // namespace

std::vector<std::int32_t> partition_geometric(const std::vector<PartitionPoint>& points,
                                              const Communicator& comm, GeometricMethod method) {
  static bool initialised = false;
  if (!initialised) {
    float version = 0.0f;
    check(Zoltan_Initialize(0, nullptr, &version), "Initialize");
    initialised = true;
  }
  std::vector<std::int32_t> parts(points.size(), comm.rank());
  Zoltan_Struct* zz = Zoltan_Create(comm.handle());
  FDEM_VERIFY(zz != nullptr, "Zoltan_Create");
  const std::string gid_count = std::to_string(gid_entries);
  Zoltan_Set_Param(zz, "DEBUG_LEVEL", "0");
  Zoltan_Set_Param(zz, "LB_METHOD",
                   method == GeometricMethod::rib   ? "RIB"
                   : method == GeometricMethod::rcb ? "RCB"
                                                    : "HSFC");
  Zoltan_Set_Param(zz, "NUM_GID_ENTRIES", gid_count.c_str());
  Zoltan_Set_Param(zz, "NUM_LID_ENTRIES", "1");
  Zoltan_Set_Param(zz, "OBJ_WEIGHT_DIM", "1");
  Zoltan_Set_Param(zz, "RETURN_LISTS", "PARTS");  // a part for every local object
  Zoltan_Set_Param(zz, "IMBALANCE_TOL", "1.02");
  auto* data = const_cast<std::vector<PartitionPoint>*>(&points);
  Zoltan_Set_Num_Obj_Fn(zz, count_points, data);
  Zoltan_Set_Obj_List_Fn(zz, list_points, data);
  Zoltan_Set_Num_Geom_Fn(zz, dimension, data);
  Zoltan_Set_Geom_Multi_Fn(zz, coordinates, data);
  int changes = 0, n_gid = 0, n_lid = 0, n_import = 0, n_export = 0;
  ZOLTAN_ID_PTR import_gids = nullptr, import_lids = nullptr, export_gids = nullptr,
                export_lids = nullptr;
  int *import_procs = nullptr, *import_parts = nullptr, *export_procs = nullptr,
      *export_parts = nullptr;
  check(Zoltan_LB_Partition(zz, &changes, &n_gid, &n_lid, &n_import, &import_gids, &import_lids,
                            &import_procs, &import_parts, &n_export, &export_gids, &export_lids,
                            &export_procs, &export_parts),
        "LB_Partition");
  // RETURN_LISTS = PARTS: the "export" lists hold every local object with its new part.
  FDEM_VERIFY(static_cast<std::size_t>(n_export) == points.size(), "Zoltan returns every part");
  for (int i = 0; i < n_export; ++i) parts[export_lids[i * n_lid]] = export_parts[i];
  Zoltan_LB_Free_Part(&import_gids, &import_lids, &import_procs, &import_parts);
  Zoltan_LB_Free_Part(&export_gids, &export_lids, &export_procs, &export_parts);
  Zoltan_Destroy(&zz);
  keep_parts_on_their_ranks(parts, points, comm);
  return parts;
}

}  // namespace fdem
