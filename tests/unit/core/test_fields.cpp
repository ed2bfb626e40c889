// The field tables (core/fields.hpp): every field travels through a packed row bit for bit, the
// ones that do not migrate start at their fill, absent optional fields read their fallback, and
// state_hash is the sum it was before the tables (gid, x, v per node).
#include <catch2/catch.hpp>
#include <cstring>
#include <type_traits>
#include <vector>

#include "core/fields.hpp"
#include "core/state_hash.hpp"

using namespace fdem;

namespace {

// Entry values that differ per field, entry and component.
template <class Arrays, std::size_t N>
void fill_pattern(const std::array<Field<Arrays>, N>& table, Arrays& arrays, int seed) {
  int field_index = 0;
  for_each_field_array(table, arrays, [&](const auto& field, auto& values) {
    using T = typename std::decay_t<decltype(values)>::value_type;
    for (std::size_t i = 0; i < values.size(); ++i)
      values[i] = static_cast<T>(std::is_floating_point_v<T>
                                     ? 0.25 * double(i) + 10.0 * field_index + seed + 0.125
                                     : double((i + 3 * field_index + seed) % 100));
    (void)field;
    ++field_index;
  });
}

// Entry `a` of `from` and entry `b` of `to` agree in every field with `use`; the others of `to`
// hold their fill.
template <class Arrays, std::size_t N>
void check_entry(const std::array<Field<Arrays>, N>& table, const Arrays& from, std::size_t a,
                 const Arrays& to, std::size_t b, unsigned use) {
  for (const Field<Arrays>& field : table) {
    INFO("field " << field.name);
    std::vector<unsigned char> want(field.bytes()), got(field.bytes()), fill(field.bytes());
    field.copy_out(from, a, want.data());
    field.copy_out(to, b, got.data());
    Arrays fresh;  // one entry holding the fill
    field.apply(fresh, [&](auto& values) {
      using T = typename std::decay_t<decltype(values)>::value_type;
      values.assign(static_cast<std::size_t>(field.components), static_cast<T>(field.fill));
    });
    field.copy_out(fresh, 0, fill.data());
    CHECK(got == (field.has(use) ? want : fill));
  }
}

template <class Arrays, std::size_t N>
void round_trip(const std::array<Field<Arrays>, N>& table, Arrays& from, Arrays& to) {
  fill_pattern(table, from, 1);
  fill_pattern(table, to, 7);  // every field of entry 0 of `to` differs before
  std::vector<unsigned char> row(field_bytes(table, FieldUse::migrates));
  const unsigned char* end = pack_fields(table, FieldUse::migrates, from, 1, row.data());
  CHECK(end == row.data() + row.size());
  CHECK(unpack_fields(table, FieldUse::migrates, to, 0, row.data()) == end);
  check_entry(table, from, 1, to, 0, FieldUse::migrates);
}

}  // namespace

TEST_CASE(
    "fields: every field of the tables travels in a packed row bit for bit, the ones that "
    "do not migrate start at their fill",
    "[core][fields]") {
  SECTION("nodes") {
    NodeArrays from, to;
    from.resize(3);
    to.resize(2);
    round_trip(node_fields, from, to);
    // The force is summed anew every step: it does not travel.
    CHECK(to.f[0] == 0.0);
    // x, v, prescribed velocity, mass, piece, constrained; the reference position travels as
    // three doubles beside them (parallel/distribution_rows.hpp), its local index not at all.
    CHECK(to.reference[0] == -1);
    CHECK(field_bytes(node_fields, FieldUse::migrates) == (3 * 3 + 1) * 8 + 4 + 1);
  }
  SECTION("tets") {
    TetArrays from, to;
    from.contact_group.resize(1);  // present: resized with the others
    to.contact_group.resize(1);
    from.resize(3);
    to.resize(2);
    CHECK(from.contact_group.size() == 3);
    round_trip(tet_fields, from, to);
  }
  SECTION("joints") {
    JointArrays from, to;
    from.resize(3);
    to.resize(2);
    round_trip(joint_fields, from, to);
  }
}

TEST_CASE(
    "fields: new entries hold their fill, an absent optional field stays absent, reads "
    "its fallback and ignores writes",
    "[core][fields]") {
  JointArrays joints;
  joints.resize(2);
  CHECK(joints.broken == std::vector<std::uint8_t>{0, 0});
  NodeArrays nodes;
  nodes.resize(2);
  CHECK(nodes.reference == std::vector<std::int32_t>{-1, -1});

  TetArrays tets;  // contact_group absent: a tet's group is its piece
  tets.resize(2);
  CHECK(tets.contact_group.empty());
  tets.piece = {5, 9};
  const auto named = [](const char* name) -> const Field<TetArrays>& {
    for (const Field<TetArrays>& field : tet_fields)
      if (std::string(field.name) == name) return field;
    FAIL("no tet field " << name);
    return tet_fields.front();
  };
  const Field<TetArrays>& group = named("contact_group");
  std::int32_t value = 0;
  group.copy_out(tets, 1, reinterpret_cast<unsigned char*>(&value));
  CHECK(value == 9);
  value = 4;
  group.copy_in(tets, 0, reinterpret_cast<const unsigned char*>(&value));
  group.reset(tets, 0);
  CHECK(tets.contact_group.empty());
  // contact_faces absent (potential contact): reads its fill, two values per tet.
  CHECK(tets.contact_faces.empty());
  const Field<TetArrays>& faces = named("contact_faces");
  std::int32_t bits[2] = {7, 7};
  faces.copy_out(tets, 1, reinterpret_cast<unsigned char*>(bits));
  CHECK(bits[0] == 0);
  CHECK(bits[1] == 0);

  TravellingState state;  // no joints: no joint states
  const auto& joint_state = travelling_tet_fields.front();
  std::uint8_t byte = 7;
  joint_state.copy_out(state, 3, &byte);
  CHECK(byte == 0);
}

TEST_CASE(
    "fields: state_hash sums FNV-1a of (gid − offset, x, v) per owned node, finished by "
    "splitmix64, as before the field tables",
    "[core][fields][hash]") {
  NodeArrays nodes;
  nodes.resize(4);
  nodes.n_owned = 3;
  for (LocalIndex n = 0; n < 4; ++n) {
    nodes.gid[n] = 100 + 2 * n;
    const double reference[3] = {99.0, 99.0, 99.0};  // not hashed
    nodes.add_reference(n, reference);
    for (int k = 0; k < 3; ++k) {
      nodes.x[3 * n + k] = 0.1 * n - 0.3 * k;
      nodes.v[3 * n + k] = -2.0 * n + 0.7 * k;
    }
  }
  const GlobalId offset = 100;
  std::uint64_t sum = 0;
  for (LocalIndex n = 0; n < nodes.n_owned; ++n) {
    std::vector<unsigned char> bytes(8 + 48);
    const GlobalId index = nodes.gid[n] - offset;
    std::memcpy(bytes.data(), &index, 8);
    std::memcpy(bytes.data() + 8, &nodes.x[3 * n], 24);
    std::memcpy(bytes.data() + 32, &nodes.v[3 * n], 24);
    std::uint64_t h = 0xcbf29ce484222325ULL;
    for (unsigned char c : bytes) {
      h ^= c;
      h *= 0x100000001b3ULL;
    }
    h ^= h >> 30;
    h *= 0xbf58476d1ce4e5b9ULL;
    h ^= h >> 27;
    h *= 0x94d049bb133111ebULL;
    sum += h ^ (h >> 31);
  }
  CHECK(state_hash(nodes, offset) == sum);
}
