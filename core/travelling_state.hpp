// The stage state outside Model that moves with the local entries when the model is
// (re)distributed: plain records the stages pack and unpack (the contact stage its positions at
// detection, its tets' joint states and its friction pairs; the joint stage its joints' history),
// so that the distribution (parallel/) moves them without knowing what they mean.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/types.hpp"

namespace fdem {

// What a tet's joints allow in contact; one byte that travels with the tet.  `enclosed`: bonded
// on all four faces, in a `joints: all` body, with no corner on the body mesh's boundary
// (TetArrays::enclosed): while no joint of its body has broken, nothing can overlap it without
// first crossing a whole layer of the body's tets, so it takes no part in contact.
enum class TetJointState : std::uint8_t { none, intact, cracked, enclosed };

// State a stage keeps for a pair of tets, keyed by their global ids (a < b); it travels with tet
// a.  The values are the stage's (contact friction: the stick spring (m, 3) and its stiffness
// (N/m)).
struct PairRecord {
  GlobalId a = 0, b = 0;
  double value[12] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
};

// A candidate pair of the last contact detection by global ids (a < b); travels with tet a.
struct GidPair {
  GlobalId a = 0, b = 0;
};

struct TravellingState {
  std::vector<double> x_at_detection;         // 3 per local node (m); tet boxes span them too
  std::vector<std::uint8_t> tet_joint_state;  // per local tet, a TetJointState (empty: no joints)
  // Per local joint, an opaque record of joint_record_bytes (0: the scene has no joint stage).
  std::size_t joint_record_bytes = 0;
  std::vector<std::uint8_t> joint_records;
  std::vector<PairRecord> pairs;  // held here, sorted by (a, b)
  // The contact candidates of the last detection, when they travel (a migration between
  // detections: the receiving ranks keep them instead of repeating the detection); sorted by
  // (a, b).
  std::vector<GidPair> candidates;
};

}  // namespace fdem
