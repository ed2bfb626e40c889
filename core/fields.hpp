// Every per-node, per-tet and per-joint field of the model and of the stages' travelling state,
// declared once with what it takes part in besides the kernels that read it: migration
// (parallel/distribution_rows.hpp packs and stores the fields that migrate), the ghost exchange
// (the halo fields), checkpoints (parallel/checkpoint: one dataset per checkpoint field, written
// and restored from these tables) and state_hash.  Adding a field to NodeArrays, TetArrays or
// JointArrays without a line here fails to compile (core/model.cpp checks the structs' sizes).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "core/model.hpp"
#include "core/travelling_state.hpp"

namespace fdem {

// What a field takes part in (bit flags).
struct FieldUse {
  static constexpr unsigned migrates = 1u;    // travels with its entry; else reset on arrival
  static constexpr unsigned halo = 2u;        // ghost copies refreshed every step (doubles)
  static constexpr unsigned checkpoint = 4u;  // a checkpoint dataset, restored on restart
  static constexpr unsigned hash = 8u;        // part of state_hash, in table order (doubles)
};

enum class ValueType : std::uint8_t { f64, i32, u8 };
inline const char* value_type_name(ValueType type) {
  return type == ValueType::f64 ? "float64" : type == ValueType::i32 ? "int32" : "uint8";
}

// One field: a std::vector member of `Arrays` with `components` values per entry.
template <class Arrays>
struct Field {
  using F64 = std::vector<double> Arrays::*;
  using I32 = std::vector<std::int32_t> Arrays::*;
  using U8 = std::vector<std::uint8_t> Arrays::*;

  const char* name;  // the checkpoint dataset's name and the name in messages
  std::variant<F64, I32, U8> member;
  int components;
  unsigned uses;
  double fill = 0.0;  // the value of a new entry, and of an entry whose field does not migrate
  // An optional field may be absent (an empty array): reads give `fallback`'s value when it is
  // set, else `fill`, and writes are dropped.
  bool optional = false;
  I32 fallback = nullptr;

  bool has(unsigned use) const { return (uses & use) != 0; }
  ValueType type() const { return static_cast<ValueType>(member.index()); }
  std::size_t value_bytes() const {
    return std::visit(
        [](auto m) {
          using Array = std::remove_reference_t<decltype(std::declval<Arrays&>().*m)>;
          return sizeof(typename Array::value_type);
        },
        member);
  }
  std::size_t bytes() const { return static_cast<std::size_t>(components) * value_bytes(); }

  // Calls f(std::vector<T>&) with the field's array.
  template <class F>
  decltype(auto) apply(Arrays& a, F&& f) const {
    return std::visit([&](auto m) -> decltype(auto) { return f(a.*m); }, member);
  }
  template <class F>
  decltype(auto) apply(const Arrays& a, F&& f) const {
    return std::visit([&](auto m) -> decltype(auto) { return f(a.*m); }, member);
  }

  // Exactly `n` entries; new ones hold `fill`.  An absent optional field stays absent.
  void resize(Arrays& a, std::size_t n) const {
    apply(a, [&](auto& values) {
      using T = typename std::decay_t<decltype(values)>::value_type;
      if (values.empty() && optional) return;
      resize_exact(values, n * static_cast<std::size_t>(components), static_cast<T>(fill));
    });
  }
  // The entry's bytes() bytes to `out`.
  void copy_out(const Arrays& a, std::size_t entry, unsigned char* out) const {
    apply(a, [&](const auto& values) {
      using T = typename std::decay_t<decltype(values)>::value_type;
      const std::size_t width = static_cast<std::size_t>(components);
      if (values.empty() && optional) {
        for (std::size_t k = 0; k < width; ++k) {
          const T value =
              fallback ? static_cast<T>((a.*fallback)[entry * width + k]) : static_cast<T>(fill);
          std::memcpy(out + k * sizeof(T), &value, sizeof(T));
        }
        return;
      }
      std::memcpy(out, values.data() + entry * width, width * sizeof(T));
    });
  }
  // The entry from bytes() bytes at `in`.
  void copy_in(Arrays& a, std::size_t entry, const unsigned char* in) const {
    apply(a, [&](auto& values) {
      using T = typename std::decay_t<decltype(values)>::value_type;
      const std::size_t width = static_cast<std::size_t>(components);
      if (values.empty() && optional) return;
      std::memcpy(values.data() + entry * width, in, width * sizeof(T));
    });
  }
  // The entry set to `fill`.
  void reset(Arrays& a, std::size_t entry) const {
    apply(a, [&](auto& values) {
      using T = typename std::decay_t<decltype(values)>::value_type;
      const std::size_t width = static_cast<std::size_t>(components);
      if (values.empty() && optional) return;
      std::fill_n(values.begin() + static_cast<std::ptrdiff_t>(entry * width), width,
                  static_cast<T>(fill));
    });
  }
};

// Nodes (besides gid and n_owned, their identity and roles, and reference_positions, the table
// `reference` indexes).  A node's reference position travels as its three doubles, after the
// fields (parallel/distribution_rows.hpp): its index means nothing on another rank.
inline const std::array<Field<NodeArrays>, 8> node_fields = {{
    {"x", &NodeArrays::x, 3,
     FieldUse::migrates | FieldUse::halo | FieldUse::checkpoint | FieldUse::hash},
    {"reference", &NodeArrays::reference, 1, 0, -1.0},
    {"v", &NodeArrays::v, 3,
     FieldUse::migrates | FieldUse::halo | FieldUse::checkpoint | FieldUse::hash},
    {"f", &NodeArrays::f, 3, 0},  // summed anew every step
    {"mass", &NodeArrays::mass, 1, FieldUse::migrates},
    {"piece", &NodeArrays::piece, 1, FieldUse::migrates},
    {"constrained", &NodeArrays::constrained, 1, FieldUse::migrates},
    {"prescribed_velocity", &NodeArrays::prescribed_velocity, 3,
     FieldUse::migrates | FieldUse::checkpoint, 0.0, true},  // absent: NodeArrays says when
}};

// Tets (besides gid, nodes, n_owned and the roles owned / active, which the distribution sets,
// and `enclosed`, read once at start-up and carried by the contact stage's joint state).
inline const std::array<Field<TetArrays>, 8> tet_fields = {{
    {"dm_inv", &TetArrays::dm_inv, 9, FieldUse::migrates},
    {"volume0", &TetArrays::volume0, 1, FieldUse::migrates},
    {"material", &TetArrays::material, 1, FieldUse::migrates},
    {"piece", &TetArrays::piece, 1, FieldUse::migrates},
    {"viscosity", &TetArrays::viscosity, 1, FieldUse::migrates},
    {"dashpot_mass", &TetArrays::dashpot_mass, 1, FieldUse::migrates},
    {"contact_group", &TetArrays::contact_group, 1, FieldUse::migrates, 0.0, true,
     &TetArrays::piece},
    {"contact_faces", &TetArrays::contact_faces, 2, FieldUse::migrates, 0.0, true},
}};

// Joints (besides gid, nodes and tets, their identity).
inline const std::array<Field<JointArrays>, 4> joint_fields = {{
    {"area0", &JointArrays::area0, 1, FieldUse::migrates},
    {"law", &JointArrays::law, 1, FieldUse::migrates},
    {"broken", &JointArrays::broken, 1, FieldUse::migrates | FieldUse::checkpoint},
    {"mode", &JointArrays::mode, 1, FieldUse::migrates | FieldUse::checkpoint},
}};

// The stages' per-node and per-tet state that travels (TravellingState): the contact stage's
// positions at the last detection and its tets' joint states.  (Per-joint and per-pair state
// travels as the stages' opaque records.)
inline const std::array<Field<TravellingState>, 1> travelling_node_fields = {{
    {"x_at_detection", &TravellingState::x_at_detection, 3,
     FieldUse::migrates | FieldUse::checkpoint},
}};
inline const std::array<Field<TravellingState>, 1> travelling_tet_fields = {{
    {"joint_state", &TravellingState::tet_joint_state, 1, FieldUse::migrates, 0.0, true},
}};

// The contact stage's per-pair state, in PairRecord::value in this order: a friction pair's stick
// spring (m), its stiffness (N/m) and its anchors (barycentric weights in tet a, then in tet b).
// Pairs travel with their first tet and are checkpointed.
struct PairField {
  const char* name;
  int components;
};
inline constexpr std::array<PairField, 4> pair_record_fields = {
    {{"spring", 3}, {"stiffness", 1}, {"anchor_a", 4}, {"anchor_b", 4}}};
constexpr int pair_record_values() {
  int values = 0;
  for (const PairField& field : pair_record_fields) values += field.components;
  return values;
}
static_assert(pair_record_values() <= static_cast<int>(sizeof(PairRecord::value) / sizeof(double)),
              "the pair fields fit PairRecord::value");

// Bytes per entry of the fields of `table` that have `use`.
template <class Arrays, std::size_t N>
std::size_t field_bytes(const std::array<Field<Arrays>, N>& table, unsigned use) {
  std::size_t bytes = 0;
  for (const Field<Arrays>& field : table)
    if (field.has(use)) bytes += field.bytes();
  return bytes;
}

// Entry `entry`'s fields with `use`, in table order, to `out` (field_bytes bytes); returns the
// end.
template <class Arrays, std::size_t N>
unsigned char* pack_fields(const std::array<Field<Arrays>, N>& table, unsigned use, const Arrays& a,
                           std::size_t entry, unsigned char* out) {
  for (const Field<Arrays>& field : table)
    if (field.has(use)) {
      field.copy_out(a, entry, out);
      out += field.bytes();
    }
  return out;
}

// The reverse: fields with `use` from `in`; the others are reset to their fill.  Returns the end.
template <class Arrays, std::size_t N>
const unsigned char* unpack_fields(const std::array<Field<Arrays>, N>& table, unsigned use,
                                   Arrays& a, std::size_t entry, const unsigned char* in) {
  for (const Field<Arrays>& field : table)
    if (field.has(use)) {
      field.copy_in(a, entry, in);
      in += field.bytes();
    } else {
      field.reset(a, entry);
    }
  return in;
}

// Calls f(field, array) for every field of `table` whose array is present.
template <class Arrays, std::size_t N, class F>
void for_each_field_array(const std::array<Field<Arrays>, N>& table, Arrays& a, F&& f) {
  for (const Field<Arrays>& field : table)
    field.apply(a, [&](auto& values) {
      if (!(values.empty() && field.optional)) f(field, values);
    });
}

}  // namespace fdem
