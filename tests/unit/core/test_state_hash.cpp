// state_hash: a sum of per-node fingerprints — the same for any node order and any split of the
// nodes among ranks (partial sums add up), and different when one bit of one node changes.
#include <catch2/catch.hpp>
#include <cstring>
#include <random>

#include "core/state_hash.hpp"

using namespace fdem;

namespace {

NodeArrays random_nodes(LocalIndex n, std::uint64_t seed) {
  NodeArrays nodes;
  nodes.resize(n);
  nodes.n_owned = n;
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (LocalIndex i = 0; i < n; ++i) {
    nodes.gid[i] = 3 * i + 7;
    for (int k = 0; k < 3; ++k) {
      nodes.x[3 * i + k] = uniform(random);
      nodes.v[3 * i + k] = uniform(random);
    }
    const double reference[3] = {uniform(random), uniform(random), uniform(random)};
    nodes.add_reference(i, reference);
  }
  return nodes;
}

// Nodes [first, last) of `all` as a rank holding only them would.
NodeArrays slice(const NodeArrays& all, LocalIndex first, LocalIndex last) {
  NodeArrays part;
  part.resize(last - first);
  part.n_owned = last - first;
  for (LocalIndex i = first; i < last; ++i) {
    part.gid[i - first] = all.gid[i];
    for (int k = 0; k < 3; ++k) {
      part.x[3 * (i - first) + k] = all.x[3 * i + k];
      part.v[3 * (i - first) + k] = all.v[3 * i + k];
    }
  }
  return part;
}

}  // namespace

TEST_CASE("state_hash: independent of node order and of the split among ranks", "[core][hash]") {
  const NodeArrays nodes = random_nodes(1000, 1);
  const std::uint64_t whole = state_hash(nodes, 0);
  // Reversed order.
  NodeArrays reversed = slice(nodes, 0, nodes.size());
  for (LocalIndex i = 0; i < nodes.size(); ++i) {
    const LocalIndex j = nodes.size() - 1 - i;
    reversed.gid[j] = nodes.gid[i];
    for (int k = 0; k < 3; ++k) {
      reversed.x[3 * j + k] = nodes.x[3 * i + k];
      reversed.v[3 * j + k] = nodes.v[3 * i + k];
    }
  }
  CHECK(state_hash(reversed, 0) == whole);
  // Three "ranks": their hashes add up (modulo 2^64) to the whole one.
  const std::uint64_t parts = state_hash(slice(nodes, 0, 123), 0) +
                              state_hash(slice(nodes, 123, 640), 0) +
                              state_hash(slice(nodes, 640, 1000), 0);
  CHECK(parts == whole);
  // Ghost entries (beyond n_owned) do not count.
  NodeArrays with_ghosts = nodes;
  with_ghosts.n_owned = 640;
  CHECK(state_hash(with_ghosts, 0) == state_hash(slice(nodes, 0, 640), 0));
}

TEST_CASE("state_hash: one flipped bit of one node changes it", "[core][hash]") {
  const NodeArrays nodes = random_nodes(200, 2);
  const std::uint64_t whole = state_hash(nodes, 0);
  for (int bit : {0, 17, 52, 63}) {
    NodeArrays changed = nodes;
    std::uint64_t word;
    std::memcpy(&word, &changed.v[3 * 77 + 1], sizeof(word));
    word ^= std::uint64_t{1} << bit;
    std::memcpy(&changed.v[3 * 77 + 1], &word, sizeof(word));
    CHECK(state_hash(changed, 0) != whole);
  }
  NodeArrays renumbered = nodes;
  std::swap(renumbered.gid[3], renumbered.gid[4]);  // same values on other nodes
  CHECK(state_hash(renumbered, 0) != whole);
  CHECK(reference_hash(nodes, 0) != whole);
}

TEST_CASE("state_hash: the same for any gid offset, hashing gid − offset", "[core][hash]") {
  const NodeArrays nodes = random_nodes(300, 3);
  const std::uint64_t whole = state_hash(nodes, 0), reference = reference_hash(nodes, 0);
  // Offsets above 2^32 and near 2^62 (the scene key's limit): a truncated gid would change it.
  for (GlobalId offset : {GlobalId{1} << 32, (GlobalId{1} << 32) + 12345, GlobalId{1} << 40,
                          (GlobalId{1} << 62) - 1}) {
    NodeArrays shifted = nodes;
    for (GlobalId& g : shifted.gid) g += offset;
    CHECK(state_hash(shifted, offset) == whole);
    CHECK(reference_hash(shifted, offset) == reference);
    CHECK(state_hash(shifted, 0) != whole);  // the gid counts, not only the values
  }
}
