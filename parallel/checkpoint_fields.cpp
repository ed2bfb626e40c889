#include "parallel/checkpoint_fields.hpp"

#include <algorithm>
#include <cstring>
#include <type_traits>
#include <variant>

#include "core/error.hpp"
#include "core/fields.hpp"

namespace fdem {

namespace {

template <class Arrays, std::size_t N>
void add_columns(const std::array<Field<Arrays>, N>& table, std::vector<CheckpointColumn>& out) {
  for (const Field<Arrays>& field : table) {
    if (!field.has(FieldUse::checkpoint)) continue;
    CheckpointColumn& column = out.emplace_back();
    column.name = field.name;
    column.components = static_cast<std::size_t>(field.components);
    std::visit(
        [&](auto member) {
          using Values = std::remove_reference_t<decltype(std::declval<Arrays&>().*member)>;
          column.values = Values{};
        },
        field.member);
  }
}

// Appends entry `entry` of every checkpoint field of `table` to the next columns from `column`.
template <class Arrays, std::size_t N>
void append_entry(const std::array<Field<Arrays>, N>& table, const Arrays& arrays,
                  std::size_t entry, CheckpointColumn*& column) {
  for (const Field<Arrays>& field : table) {
    if (!field.has(FieldUse::checkpoint)) continue;
    field.apply(arrays, [&](const auto& values) {
      auto& out = std::get<std::decay_t<decltype(values)>>(column->values);
      const std::size_t width = column->components;
      if (values.empty() && field.optional) {  // absent: its fill (or fallback) values
        out.resize(out.size() + width);
        field.copy_out(arrays, entry,
                       reinterpret_cast<unsigned char*>(out.data() + out.size() - width));
        return;
      }
      out.insert(out.end(), values.begin() + static_cast<std::ptrdiff_t>(entry * width),
                 values.begin() + static_cast<std::ptrdiff_t>((entry + 1) * width));
    });
    ++column;
  }
}

// The reverse: row `row` of the next columns into entry `entry`.
template <class Arrays, std::size_t N>
void store_entry(const std::array<Field<Arrays>, N>& table, std::size_t row, Arrays& arrays,
                 std::size_t entry, const CheckpointColumn*& column) {
  for (const Field<Arrays>& field : table) {
    if (!field.has(FieldUse::checkpoint)) continue;
    std::visit(
        [&](const auto& values) {
          const auto* bytes =
              reinterpret_cast<const unsigned char*>(values.data() + row * column->components);
          field.copy_in(arrays, entry, bytes);
        },
        column->values);
    ++column;
  }
}

}  // namespace

CheckpointRows checkpoint_layout(std::size_t joint_record_bytes) {
  CheckpointRows rows;
  add_columns(node_fields, rows.nodes.columns);
  add_columns(travelling_node_fields, rows.nodes.columns);
  add_columns(joint_fields, rows.joints.columns);
  CheckpointColumn& history = rows.joints.columns.emplace_back();
  history.name = "history";  // the fracture stage's records (opaque bytes)
  history.components = joint_record_bytes;
  history.values = std::vector<std::uint8_t>{};
  for (const PairField& field : pair_record_fields) {
    CheckpointColumn& column = rows.pair_columns.emplace_back();
    column.name = field.name;
    column.components = static_cast<std::size_t>(field.components);
    column.values = std::vector<double>{};
  }
  return rows;
}

CheckpointRows owned_checkpoint_rows(const Model& model, const TravellingState& state) {
  CheckpointRows rows = checkpoint_layout(state.joint_record_bytes);
  const GlobalId offset = model.gid_offset;
  const NodeArrays& nodes = model.nodes;
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) {
    rows.nodes.gid.push_back(nodes.gid[n] - offset);
    CheckpointColumn* column = rows.nodes.columns.data();
    append_entry(node_fields, nodes, static_cast<std::size_t>(n), column);
    append_entry(travelling_node_fields, state, static_cast<std::size_t>(n), column);
  }
  const JointArrays& joints = model.joints;
  const std::size_t record_bytes = state.joint_record_bytes;
  for (LocalIndex j = 0; j < joints.size(); ++j) {
    if (!model.tets.is_owned(joints.tets[2 * j])) continue;  // a joint lives with its tet A
    rows.joints.gid.push_back(joints.gid[j] - offset);
    CheckpointColumn* column = rows.joints.columns.data();
    append_entry(joint_fields, joints, static_cast<std::size_t>(j), column);
    auto& history = std::get<std::vector<std::uint8_t>>(column->values);
    const auto* record = state.joint_records.data() + static_cast<std::size_t>(j) * record_bytes;
    history.insert(history.end(), record, record + record_bytes);
  }
  for (const PairRecord& pair : state.pairs) {
    const LocalIndex a = model.tets.find(pair.a);
    if (a < 0 || !model.tets.is_owned(a)) continue;  // the owner of the pair's tet a writes it
    rows.pair_a.push_back(pair.a - offset);
    rows.pair_b.push_back(pair.b - offset);
    std::size_t at = 0;
    for (CheckpointColumn& column : rows.pair_columns) {
      auto& values = std::get<std::vector<double>>(column.values);
      values.insert(values.end(), pair.value + at, pair.value + at + column.components);
      at += column.components;
    }
  }
  return rows;
}

void store_checkpoint_rows(const CheckpointRows& rows, Model& model, TravellingState& state) {
  const GlobalId offset = model.gid_offset;
  NodeArrays& nodes = model.nodes;
  for (std::size_t i = 0; i < rows.nodes.gid.size(); ++i) {
    const LocalIndex n = nodes.find(rows.nodes.gid[i] + offset);
    if (n < 0) continue;
    const CheckpointColumn* column = rows.nodes.columns.data();
    store_entry(node_fields, i, nodes, static_cast<std::size_t>(n), column);
    store_entry(travelling_node_fields, i, state, static_cast<std::size_t>(n), column);
  }
  JointArrays& joints = model.joints;
  const std::size_t record_bytes = state.joint_record_bytes;
  for (std::size_t i = 0; i < rows.joints.gid.size(); ++i) {
    const GlobalId gid = rows.joints.gid[i] + offset;
    const auto it = std::lower_bound(joints.gid.begin(), joints.gid.end(), gid);
    if (it == joints.gid.end() || *it != gid) continue;
    const auto j = static_cast<std::size_t>(it - joints.gid.begin());
    const CheckpointColumn* column = rows.joints.columns.data();
    store_entry(joint_fields, i, joints, j, column);
    const auto& history = std::get<std::vector<std::uint8_t>>(column->values);
    FDEM_VERIFY(column->components == record_bytes, "joint records of this build's size");
    if (record_bytes > 0)
      std::memcpy(state.joint_records.data() + j * record_bytes, &history[i * record_bytes],
                  record_bytes);
  }
  state.pairs.clear();
  for (std::size_t i = 0; i < rows.pair_a.size(); ++i) {
    PairRecord pair;
    pair.a = rows.pair_a[i] + offset;
    pair.b = rows.pair_b[i] + offset;
    if (!std::binary_search(model.tets.gid.begin(), model.tets.gid.end(), pair.a)) continue;
    std::size_t at = 0;
    for (const CheckpointColumn& column : rows.pair_columns) {
      const auto& values = std::get<std::vector<double>>(column.values);
      std::copy_n(values.begin() + static_cast<std::ptrdiff_t>(i * column.components),
                  column.components, pair.value + at);
      at += column.components;
    }
    state.pairs.push_back(pair);
  }
}

}  // namespace fdem
