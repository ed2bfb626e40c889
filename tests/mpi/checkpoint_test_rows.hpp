// Shared by the checkpoint tests (test_checkpoint.cpp, test_checkpoint_errors.cpp): a temporary
// directory every rank sees, rows with special values (signed zero, infinity, NaN, subnormal)
// for bit-for-bit comparisons, and helpers to compare, catch and reseal.
#pragma once

#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "core/error.hpp"
#include "parallel/checkpoint.hpp"
#include "parallel/checkpoint_fields.hpp"
#include "parallel/checkpoint_seal.hpp"
#include "parallel/communicator.hpp"
#include "shared_temp_dir.hpp"

namespace fdem::checkpoint_test {

namespace fs = std::filesystem;

// Distinct values with special cases (signed zero, infinity, NaN, subnormal) so that the
// comparison really is bit for bit.
inline double node_value(int field, GlobalId gid, int component) {
  if (gid == 3 && component == 0) return -0.0;
  if (gid == 5 && component == 1) return std::numeric_limits<double>::infinity();
  if (gid == 7 && component == 2) return std::numeric_limits<double>::quiet_NaN();
  if (gid == 11 && component == 0) return std::numeric_limits<double>::denorm_min() * (field + 1);
  return std::sin(1.0 + 0.37 * static_cast<double>(gid) + 0.11 * component + 10.0 * field) *
         std::pow(10.0, field - 2);
}
inline std::uint8_t history_byte(GlobalId gid, std::size_t b) {
  return static_cast<std::uint8_t>((gid * 31 + static_cast<GlobalId>(b) * 7 + 1) & 0xff);
}

struct FileScene {
  std::int64_t n_nodes = 1000, n_joints = 300;
  std::size_t history_bytes = 12;
  int friction_per_writer = 3;
};

// The header every rank passes (the same everywhere).
inline CheckpointHeader make_header(const FileScene& scene) {
  CheckpointHeader h;
  h.n_nodes = scene.n_nodes;
  h.n_tets = 4321;
  h.n_joints = scene.n_joints;
  h.reference_hash = 0xfedcba9876543210ULL;
  h.doubles = {{"time", 1.25e-3}, {"dt", 1e-7}, {"energy_in", -3.5e4}, {"alpha", 0.1}};
  h.integers = {
      {"step", 12345}, {"detections", -7}, {"largest", std::numeric_limits<std::int64_t>::max()}};
  return h;
}

// One row of `columns` (the k-th column's values from pattern k: doubles with the special cases,
// integers and bytes from the gid).
inline void add_row(std::vector<CheckpointColumn>& columns, GlobalId g) {
  for (std::size_t k = 0; k < columns.size(); ++k) {
    CheckpointColumn& column = columns[k];
    const int field = static_cast<int>(k);
    for (std::size_t i = 0; i < column.components; ++i)
      std::visit(
          [&](auto& values) {
            using T = typename std::decay_t<decltype(values)>::value_type;
            if constexpr (std::is_floating_point_v<T>)
              values.push_back(node_value(field, g, static_cast<int>(i)));
            else
              values.push_back(static_cast<T>(history_byte(g + 1000 * field, i)));
          },
          column.values);
  }
}
inline void add_node(CheckpointRows& rows, GlobalId g) {
  rows.nodes.gid.push_back(g);
  add_row(rows.nodes.columns, g);
}
inline void add_joint(CheckpointRows& rows, GlobalId j) {
  rows.joints.gid.push_back(j);
  add_row(rows.joints.columns, j);
}
// Friction pairs of writer `w`: a deliberately not sorted, so the reader's sort is exercised.
inline void add_friction(CheckpointRows& rows, const FileScene& scene, int writer) {
  for (int k = scene.friction_per_writer - 1; k >= 0; --k) {
    const GlobalId a = 900 - 10 * writer - k, b = a + 1 + k;
    rows.pair_a.push_back(a);
    rows.pair_b.push_back(b);
    for (CheckpointColumn& column : rows.pair_columns)
      for (std::size_t c = 0; c < column.components; ++c)
        std::get<std::vector<double>>(column.values)
            .push_back(1e-6 * (a + double(c)) - 1e-7 * b + double(column.components));
  }
}
// The columns fdem writes (parallel/checkpoint_fields), with joint records of `history_bytes`.
inline CheckpointRows empty_rows(const FileScene& scene) {
  return checkpoint_layout(scene.history_bytes);
}

// What `writer` of `writers` owns: nodes interleaved (gid % writers), joints by another pattern,
// `owner_of` may leave some writers without rows.
template <class NodeOwner, class JointOwner>
inline CheckpointRows make_owned(const FileScene& scene, int writer, NodeOwner node_owner,
                                 JointOwner joint_owner) {
  CheckpointRows rows = empty_rows(scene);
  // Descending gid order, so the writer's own sort to file positions is exercised.
  for (GlobalId g = scene.n_nodes - 1; g >= 0; --g)
    if (node_owner(g) == writer) add_node(rows, g);
  for (GlobalId j = 0; j < scene.n_joints; ++j)
    if (joint_owner(j) == writer) add_joint(rows, j);
  add_friction(rows, scene, writer);
  return rows;
}
inline CheckpointRows interleaved(const FileScene& scene, int writer, int writers) {
  return make_owned(
      scene, writer, [&](GlobalId g) { return static_cast<int>(g % writers); },
      [&](GlobalId j) { return static_cast<int>((j / 7) % writers); });
}

// Everything, sorted as read_checkpoint returns it, for `writers` writers with friction.
inline CheckpointRows expected_rows(const FileScene& scene, int writers) {
  CheckpointRows all = empty_rows(scene);
  for (GlobalId g = 0; g < scene.n_nodes; ++g) add_node(all, g);
  for (GlobalId j = 0; j < scene.n_joints; ++j) add_joint(all, j);
  CheckpointRows pairs = empty_rows(scene);
  for (int w = 0; w < writers; ++w) add_friction(pairs, scene, w);
  std::vector<std::size_t> order(pairs.pair_a.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    return std::make_pair(pairs.pair_a[i], pairs.pair_b[i]) <
           std::make_pair(pairs.pair_a[j], pairs.pair_b[j]);
  });
  for (std::size_t i : order) {
    all.pair_a.push_back(pairs.pair_a[i]);
    all.pair_b.push_back(pairs.pair_b[i]);
    for (std::size_t k = 0; k < pairs.pair_columns.size(); ++k) {
      const std::size_t width = pairs.pair_columns[k].components;
      const auto& from = std::get<std::vector<double>>(pairs.pair_columns[k].values);
      auto& to = std::get<std::vector<double>>(all.pair_columns[k].values);
      to.insert(to.end(), from.begin() + static_cast<std::ptrdiff_t>(i * width),
                from.begin() + static_cast<std::ptrdiff_t>((i + 1) * width));
    }
  }
  return all;
}

template <class T>
inline bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

inline void check_columns_equal(const std::vector<CheckpointColumn>& got,
                                const std::vector<CheckpointColumn>& want) {
  CHECK(got.size() == want.size());
  for (std::size_t k = 0; k < std::min(got.size(), want.size()); ++k) {
    INFO("column " << want[k].name);
    CHECK(got[k].name == want[k].name);
    CHECK(got[k].components == want[k].components);
    CHECK(got[k].type() == want[k].type());
    if (got[k].type() == want[k].type())
      std::visit(
          [&](const auto& values) {
            CHECK(same_bits(values, std::get<std::decay_t<decltype(values)>>(want[k].values)));
          },
          got[k].values);
  }
}

inline void check_rows_equal(const CheckpointRows& got, const CheckpointRows& want) {
  CHECK(got.nodes.gid == want.nodes.gid);
  CHECK(std::is_sorted(got.nodes.gid.begin(), got.nodes.gid.end()));
  check_columns_equal(got.nodes.columns, want.nodes.columns);
  CHECK(got.joints.gid == want.joints.gid);
  CHECK(std::is_sorted(got.joints.gid.begin(), got.joints.gid.end()));
  check_columns_equal(got.joints.columns, want.joints.columns);
  CHECK(got.pair_a == want.pair_a);
  CHECK(got.pair_b == want.pair_b);
  check_columns_equal(got.pair_columns, want.pair_columns);
}

inline void check_header_equal(const CheckpointHeader& got, const CheckpointHeader& want,
                               int ranks) {
  CHECK(got.n_nodes == want.n_nodes);
  CHECK(got.n_tets == want.n_tets);
  CHECK(got.n_joints == want.n_joints);
  CHECK(got.reference_hash == want.reference_hash);
  CHECK(got.ranks == ranks);
  CHECK(got.integers == want.integers);
  CHECK(got.doubles.size() == want.doubles.size());
  for (std::size_t i = 0; i < std::min(got.doubles.size(), want.doubles.size()); ++i) {
    CHECK(got.doubles[i].first == want.doubles[i].first);
    CHECK(std::memcmp(&got.doubles[i].second, &want.doubles[i].second, sizeof(double)) == 0);
  }
}

// Runs `body` and returns what this rank caught: "input:<message>", "internal:<message>",
// "io:<message>", "other" or "none".
template <class Body>
inline std::string caught(Body&& body) {
  try {
    body();
    return "none";
  } catch (const CollectiveInputError& e) {
    return std::string("input:") + e.what();
  } catch (const CollectiveInternalError& e) {
    return std::string("internal:") + e.what();
  } catch (const CollectiveIoError& e) {
    return std::string("io:") + e.what();
  } catch (...) {
    return "other";
  }
}

// Writes the seal of an HDF5 file edited after fdem wrote it (every dataset's raw data found).
inline void reseal(const std::string& path) {
  std::vector<FileRegion> regions;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  for (const char* group : {"/nodes", "/joints", "/friction"})
    for (const char* name : {"gid", "x", "v", "x_at_detection", "prescribed_velocity", "broken",
                             "mode", "history", "a", "b", "spring", "stiffness"}) {
      const std::string full = std::string(group) + "/" + name;
      if (H5Lexists(file, group, H5P_DEFAULT) <= 0 ||
          H5Lexists(file, full.c_str(), H5P_DEFAULT) <= 0)
        continue;
      const hid_t set = H5Dopen2(file, full.c_str(), H5P_DEFAULT);
      const haddr_t offset = H5Dget_offset(set);
      if (offset != HADDR_UNDEF) regions.push_back({offset, H5Dget_storage_size(set)});
      H5Dclose(set);
    }
  H5Fclose(file);
  write_checkpoint_seal(path, regions);
}

inline bool same_on_all_ranks(const Communicator& comm, const std::string& text) {
  return comm.sum<std::int32_t>(comm.broadcast(text, 0) == text ? 0 : 1) == 0;
}

inline std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace fdem::checkpoint_test
