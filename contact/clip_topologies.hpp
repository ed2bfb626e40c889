// Every clip graph a rank has met, shared by all its pairs (potential_contact.cpp).  A sub-tet's
// clip by the other tet's four planes is decided by which vertices each plane cuts off: the
// same outside masks plane after plane give the same cut edges, the same new vertices in the same
// order and the same faces (clip_replay.hpp).  The sub-tets all start from one vertex graph, so
// the masks alone lead, as in a trie, to the clip's record.  A piece whose vertex crossed a plane
// since the step before (its pair's record no longer fits) finds its new clip here, made once by
// some pair, instead of clipping afresh: where meshes meet aligned a vertex hovers over a plane
// (wall55: 0.29 fresh clips per pair and step, nearly all on one vertex within 1e-7 of a plane),
// and its pieces go through few graphs (wall55: 11,468 distinct ones in 1.03 M fresh clips).  The
// same operations in the same order: bit for bit, whatever the trie holds.
#pragma once

#include <cstdint>
#include <vector>

#include "contact/piece_clipper.hpp"

namespace fdem::piece_clip {

class ClipTopologies {
 public:
  static constexpr std::uint32_t kNone = 0xFFFFFFFFu;
  // Bounds on what one rank keeps (nodes, their hash and records: under 48 MiB with the vectors'
  // slack; wall55 needs ~3 MiB); past them new graphs are clipped afresh.
  static constexpr std::size_t kMaxNodes = std::size_t{1} << 19;
  static constexpr std::size_t kMaxBytes = std::size_t{1} << 23;

  // A node: the clip of a sub-tet after some planes, reached from its root by the outside masks on
  // the way.  A terminal (the four planes done, or everything cut off) holds the whole record.
  struct Node {
    std::uint32_t parent = kNone;
    std::uint32_t edges = 0;       // offset in bytes(): the 2 n_new edges cut at the last plane
    std::uint32_t record = kNone;  // terminal: offset of [length][the piece's record]
    std::uint32_t faces = kNone;   // terminal that keeps a volume: offset of [count][its faces]
    std::uint16_t mask = 0;        // outside mask at the last plane
    std::uint8_t n_new = 0;        // vertices it made
  };

  ClipTopologies() { clear(); }
  // Forgets every clip and frees the memory.
  void clear() {
    std::vector<Node>(4).swap(nodes_);  // the roots: sub-tets 0..3, nothing cut
    std::vector<std::uint8_t>().swap(bytes_);
    std::vector<Child>(64).swap(children_);
  }

  std::uint32_t root(int sub_tet) const { return static_cast<std::uint32_t>(sub_tet); }
  const Node& node(std::uint32_t id) const { return nodes_[id]; }
  const std::uint8_t* bytes() const { return bytes_.data(); }
  std::size_t size() const { return nodes_.size(); }
  // The planes done at node `id` (0 at a root).
  int depth(std::uint32_t id) const {
    int planes = 0;
    for (; nodes_[id].parent != kNone; id = nodes_[id].parent) ++planes;
    return planes;
  }
  // The record of terminal `id` (the bytes a fresh clip's log holds) and its length.
  const std::uint8_t* record(std::uint32_t id) const {
    return bytes_.data() + nodes_[id].record + 1;
  }
  int record_length(std::uint32_t id) const { return bytes_[nodes_[id].record]; }

  // The child of `parent` reached by outside mask `mask`, or kNone.
  std::uint32_t child(std::uint32_t parent, unsigned mask) const {
    const std::size_t wrap = children_.size() - 1;
    for (std::size_t at = slot(parent, mask) & wrap;; at = (at + 1) & wrap) {
      const Child& c = children_[at];
      if (c.node == kNone || (c.parent == parent && c.mask == mask)) return c.node;
    }
  }

  // Adds a fresh clip of `sub_tet` from its log (ClipLog's bytes: per plane [mask][new][edges],
  // then the faces); returns its terminal, or kNone where the log is not whole or room is out.
  std::uint32_t add(int sub_tet, const std::uint8_t* log, int size) {
    if (nodes_.size() + 5 > kMaxNodes || bytes_.size() + 2 * size + 64 > kMaxBytes) return kNone;
    std::uint32_t at = root(sub_tet);
    const std::uint8_t* in = log;
    const std::uint8_t* const end = log + size;
    int n = 4;  // vertices alive
    for (int b = 0; b < 4; ++b) {
      if (end - in < 2) return kNone;
      const unsigned mask = in[0] | (static_cast<unsigned>(in[1]) << 8);
      in += 2;
      const bool all_out = mask == (1u << n) - 1u;  // (n <= 16 in a whole log)
      int n_new = 0;
      if (mask != 0 && !all_out) {
        if (end - in < 1) return kNone;
        n_new = *in++;
        if (end - in < 2 * n_new) return kNone;
      }
      std::uint32_t next = child(at, mask);
      if (next == kNone) {
        next = static_cast<std::uint32_t>(nodes_.size());
        Node made;
        made.mask = static_cast<std::uint16_t>(mask);
        made.n_new = static_cast<std::uint8_t>(n_new);
        made.edges = static_cast<std::uint32_t>(bytes_.size());
        bytes_.insert(bytes_.end(), in, in + 2 * n_new);
        made.parent = at;
        nodes_.push_back(made);
        insert_child(next);
      }
      in += 2 * n_new;
      at = next;
      if (all_out) break;
      n += n_new - __builtin_popcount(mask);
    }
    Node& terminal = nodes_[at];
    if (terminal.record == kNone) {
      terminal.record = static_cast<std::uint32_t>(bytes_.size());
      if (in < end) terminal.faces = terminal.record + 1 + static_cast<std::uint32_t>(in - log);
      bytes_.push_back(static_cast<std::uint8_t>(size));
      bytes_.insert(bytes_.end(), log, log + size);
    }
    return at;
  }

 private:
  struct Child {  // the key beside the node: a probe reads one line
    std::uint32_t parent = kNone, mask = 0, node = kNone;
  };
  static std::size_t slot(std::uint32_t parent, unsigned mask) {
    return (parent * std::size_t{0x9E3779B1u} + mask * std::size_t{0x85EBCA77u}) >> 7;
  }
  // Open addressing, at most half full.
  void insert_child(std::uint32_t id) {
    if (2 * (nodes_.size() - 4) > children_.size()) {
      std::vector<Child> old(2 * children_.size());
      old.swap(children_);
      for (const Child& moved : old)
        if (moved.node != kNone) place(moved);
    }
    place(Child{nodes_[id].parent, nodes_[id].mask, id});
  }
  void place(const Child& c) {
    const std::size_t wrap = children_.size() - 1;
    std::size_t at = slot(c.parent, c.mask) & wrap;
    while (children_[at].node != kNone) at = (at + 1) & wrap;
    children_[at] = c;
  }

  std::vector<Node> nodes_;
  std::vector<std::uint8_t> bytes_;
  std::vector<Child> children_;  // hash of (parent, mask) -> child
};

}  // namespace fdem::piece_clip
