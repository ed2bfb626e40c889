// A piece's clip replayed from the step before (potential_contact.cpp).  A lasting pair clips
// each of its pieces to the same vertex graph step after step: in the default example 99.7 % of
// the clipped pieces cut the same vertices at every plane as one step earlier (docs/benchmarks.md,
// "Where the default example's pairs go").  Which vertices a plane cuts off decides the whole
// graph: the same cut edges, the same new vertices in the same order, the same faces.  So a
// record of the clip (per plane: which vertices lay outside and which edges were cut; then the
// faces) lets the next step redo the same arithmetic without the graph work (the cut-edge search,
// the cap walk, the renumbering, the face walk), after checking every vertex's side.  Where one
// side differs the piece is clipped afresh.  The same operations in the same order: bit for bit,
// whatever the records hold (a restart or a migration that drops them changes nothing).
//
// A pair's record, as the contact stage keeps it between steps: for each piece that was clipped,
// [key = 4 side + sub-tet][length][the piece's bytes], pieces in the kernel's order.  A piece's
// bytes: per plane [outside mask, 16 bits][new vertices][their edges, 2 bytes each] (a plane that
// cuts off nothing ends at its mask, one that cuts off everything ends the piece); then, for a
// piece that keeps a volume, [faces] and per face [size][planes, 16 bits][its vertices].
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <utility>
#include <vector>

#include "contact/clip_topologies.hpp"
#include "contact/piece_clipper.hpp"

namespace fdem {

// A pair's or a stage's clip records: a byte buffer whose appends are inlined (std::vector's
// push_back of a byte was a call, a few per evaluated pair).  Capacity doubles as it grows and is
// kept across clear(), so a lasting scene stops allocating after its first steps.
class RecordBytes {
 public:
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const std::uint8_t* data() const { return bytes_.get(); }
  std::uint8_t* data() { return bytes_.get(); }
  void clear() { size_ = 0; }
  void shrink_to(std::size_t size) { size_ = size < size_ ? size : size_; }
  void append(const std::uint8_t* bytes, std::size_t count) {
    if (count == 0) return;  // (bytes may then be null, which memcpy must not get)
    if (count > capacity_ - size_) grow(count);
    std::memcpy(bytes_.get() + size_, bytes, count);
    size_ += count;
  }
  void append_pair(std::uint8_t first, std::uint8_t second) {
    if (2 > capacity_ - size_) grow(2);
    bytes_[size_] = first;
    bytes_[size_ + 1] = second;
    size_ += 2;
  }
  void release() {
    bytes_.reset();
    size_ = capacity_ = 0;
  }

 private:
  void grow(std::size_t count) {
    const std::size_t capacity = std::max<std::size_t>({256, 2 * capacity_, size_ + count});
    std::unique_ptr<std::uint8_t[]> bytes(new std::uint8_t[capacity]);
    if (size_ > 0) std::memcpy(bytes.get(), bytes_.get(), size_);
    bytes_ = std::move(bytes);
    capacity_ = capacity;
  }
  std::unique_ptr<std::uint8_t[]> bytes_;
  std::size_t size_ = 0, capacity_ = 0;
};

// What the contact stage hands the kernel for one pair.  Every part is optional.
struct ClipMemo {
  // The pair's record from the step before, or null; the kernel reads it forward from here.
  const std::uint8_t* previous = nullptr;
  const std::uint8_t* previous_end = nullptr;
  RecordBytes* record = nullptr;  // this evaluation's record is appended here
  // The clips met before, where a piece's record no longer fits (clip_topologies.hpp); or null.
  piece_clip::ClipTopologies* topologies = nullptr;
  std::uint32_t replayed = 0;  // pieces replayed from the record or from the clips met before
  std::uint32_t found = 0;     // of those, the pieces whose record did not fit
  std::uint32_t clipped = 0;   // pieces clipped afresh
  // How the pair came out at the step before (kNotApart: overlapping, skipped or not evaluated;
  // kClippedEmpty: it passed the face planes and the bound but clipped to nothing;
  // kApartAtAxis + k: edge–edge axis k separated it; kApartAtPlane + j: face plane j did) and,
  // out, at this one.  A pair apart mostly stays apart the same way: the plane is tested first,
  // and a pair apart at an edge–edge axis the face planes miss tries the axes first.  The same
  // decisions as without, so the same results bit for bit.
  static constexpr std::uint8_t kNotApart = 0, kClippedEmpty = 1, kApartAtAxis = 2,
                                kApartAtPlane = kApartAtAxis + 36;
  std::uint8_t apart_before = kNotApart;
  std::uint8_t apart_now = kNotApart;
  // Out: where a face plane or an edge–edge axis found the pair apart, the gap (m) it is sure to
  // keep open while its tets move less in all (apart_pairs.hpp); else 0.
  double apart_gap = 0.0;
};

// One pair's records from one evaluation to the next, for code that follows single pairs (tests,
// benchmarks); the contact stage keeps all its pairs' records in two shared buffers instead.
class PairClipRecords {
 public:
  // A memo that reads the record of the evaluation before and writes this one's; valid until
  // the next call.
  ClipMemo next() {
    const RecordBytes& read = records_[parity_];
    RecordBytes& written = records_[parity_ ^ 1];
    written.clear();
    parity_ ^= 1;
    ClipMemo memo;
    memo.previous = read.empty() ? nullptr : read.data();
    memo.previous_end = read.data() + read.size();
    memo.record = &written;
    memo.topologies = &topologies_;
    return memo;
  }

 private:
  RecordBytes records_[2];
  piece_clip::ClipTopologies topologies_;
  int parity_ = 0;
};

namespace piece_clip {

// The faces of a clipped piece, each walked counter-clockwise seen from outside, in the layout of
// the piece's record: face after face [size][planes, 16 bits: those all its vertices lie on][its
// vertices].  `bytes` points into the record of the step before (a replay: nothing is copied) or
// at `walked` (a fresh clip, whose record then copies them).
struct PieceFaces {
  static constexpr int kMaxBytes = 7 * kMaxVertices;  // 3 per face, 1 per face vertex: <= 6 n
  int count = 0;
  const std::uint8_t* bytes = nullptr;
  std::uint8_t walked[kMaxBytes];

  static unsigned planes_of(const std::uint8_t* face) {
    return face[1] | (static_cast<unsigned>(face[2]) << 8);
  }
  // The length of the faces' bytes.
  int length() const {
    const std::uint8_t* at = bytes;
    for (int f = 0; f < count; ++f) at += 3 + at[0];
    return static_cast<int>(at - bytes);
  }
};

// The faces of the piece's vertex graph, faces of fewer than three vertices dropped.  False for a
// corrupted graph (cannot happen).
inline bool walk_faces(const Piece& piece, PieceFaces& faces) {
  const int n = piece.count;
  bool used[kMaxVertices][3];
  for (int v = 0; v < n; ++v) used[v][0] = used[v][1] = used[v][2] = false;
  faces.count = 0;
  faces.bytes = faces.walked;
  int entries = 0;  // bytes written
  for (int vs = 0; vs < n; ++vs) {
    for (int es = 0; es < 3; ++es) {
      if (used[vs][es]) continue;
      std::uint8_t* face = faces.walked + entries + 3;
      int nf = 0;
      unsigned face_planes = ~0u;
      int vc = vs, e = es;
      do {
        used[vc][e] = true;
        if (nf < kMaxVertices) face[nf++] = static_cast<std::uint8_t>(vc);
        face_planes &= piece.v[vc].planes;
        const int vn = piece.v[vc].next[e];
        const int* back = piece.v[vn].next;
        const int b = back[0] == vc ? 0 : back[1] == vc ? 1 : back[2] == vc ? 2 : 3;
        if (b == 3) return false;
        vc = vn;
        e = b == 2 ? 0 : b + 1;
      } while (vc != vs && nf < kMaxVertices);
      if (nf < 3) continue;
      std::uint8_t* head = faces.walked + entries;
      head[0] = static_cast<std::uint8_t>(nf);
      head[1] = static_cast<std::uint8_t>(face_planes & 0xFFu);
      head[2] = static_cast<std::uint8_t>((face_planes >> 8) & 0xFFu);
      ++faces.count;
      entries += 3 + nf;
    }
  }
  return true;
}

// Appends the faces to a piece's log (the log turns invalid where they do not fit).
inline void log_faces(const PieceFaces& faces, ClipLog& log) {
  const int length = faces.length();
  if (!log.room(1 + length)) return;
  log.put(static_cast<unsigned>(faces.count));
  for (int j = 0; j < length; ++j) log.put(faces.bytes[j]);
}

enum class Replay { kept, clipped_away, side_changed };

// The vertices alive while a recorded clip is redone plane after plane (replay_piece,
// walk_topologies): slots of piece.v, the sub-tet's four first and the new ones appended.
class ReplayedVertices {
 public:
  ReplayedVertices() {
    for (int j = 0; j < 4; ++j) current_[j] = j;
  }
  ReplayedVertices(const ReplayedVertices&) = delete;
  ReplayedVertices& operator=(const ReplayedVertices&) = delete;

  // Bit j: alive vertex j lies outside plane k (lam[k] < 0).
  unsigned outside(const Piece& piece, int k) {
    unsigned mask = 0;
    for (int j = 0; j < n_; ++j) {
      dist_[j] = piece.v[current_[j]].lam[k];
      mask |= static_cast<unsigned>(dist_[j] < 0.0) << j;
    }
    return mask;
  }
  bool all(unsigned mask) const { return mask == (1u << n_) - 1u; }
  // Plane b (index k = 4 + b) with outside mask `mask`: keeps the vertices inside and makes one
  // on each recorded edge (`edges`: n_new pairs of alive indices, kept end first), its
  // coordinates only (the record holds the faces and their planes).  False where they would not
  // fit (cannot happen for the kernel's records: clip afresh).
  bool cut(Piece& piece, int b, unsigned mask, const std::uint8_t* edges, int n_new) {
    if (made_ + n_new > kMaxVertices) return false;
    const int k = 4 + b;
    int kept = 0;
    for (int j = 0; j < n_; ++j) {  // (no branch: the mask varies from piece to piece)
      next_[kept] = current_[j];
      kept += !((mask >> j) & 1u);
    }
    for (int q = 0; q < n_new; ++q, edges += 2) {
      const int a = edges[0], c = edges[1];
      cut_edge_values(piece.v[current_[a]], piece.v[current_[c]], dist_[a], dist_[c], k,
                      piece.v[made_]);
      next_[kept++] = made_++;
    }
    if (kept > ClipLog::kMaxStageVertices && b < 3) return false;
    std::swap(current_, next_);
    n_ = kept;
    return true;
  }
  // The piece's vertices, in the clipper's order.
  void hand_out(const Piece& piece, const PieceVertex** vertex, int& n_vertices) const {
    for (int j = 0; j < n_; ++j) vertex[j] = &piece.v[current_[j]];
    n_vertices = n_;
  }

 private:
  int slots_[2][kMaxVertices];
  int* current_ = slots_[0];
  int* next_ = slots_[1];
  int n_ = 4, made_ = 4;
  double dist_[ClipLog::kMaxStageVertices];
};

// Redoes the clip of `piece` (its sub-tet's four vertices in v[0..3], graph unused) from the
// record `bytes`: new vertices are appended to piece.v from slot 4 on; `vertex` gets the kept
// piece's vertices in the clipper's order and `faces` its faces.  side_changed: some vertex lies
// on the other side of a plane than in the record (piece.v[0..3] are untouched: clip afresh).
inline Replay replay_piece(Piece& piece, const std::uint8_t* bytes, const std::uint8_t* end,
                           const PieceVertex** vertex, int& n_vertices, PieceFaces& faces) {
  ReplayedVertices alive;
  for (int b = 0; b < 4; ++b) {
    if (end - bytes < 2) return Replay::side_changed;  // cannot happen: records are the kernel's
    const unsigned recorded = bytes[0] | (static_cast<unsigned>(bytes[1]) << 8);
    bytes += 2;
    const unsigned mask = alive.outside(piece, 4 + b);
    if (mask != recorded) return Replay::side_changed;
    if (mask == 0) continue;
    if (alive.all(mask)) return Replay::clipped_away;
    const int n_new = *bytes++;
    if (end - bytes < 2 * n_new || !alive.cut(piece, b, mask, bytes, n_new))
      return Replay::side_changed;
    bytes += 2 * n_new;
  }
  if (end - bytes < 1) return Replay::side_changed;
  faces.count = *bytes++;
  faces.bytes = bytes;
  alive.hand_out(piece, vertex, n_vertices);
  return Replay::kept;
}

// replay_piece along the clips met before: from the root of `sub_tet`, each plane's record is the
// child reached by the outside mask.  side_changed where no clip met before fits; `terminal`
// gets the node the clip ends at.
inline Replay walk_topologies(Piece& piece, int sub_tet, const ClipTopologies& topologies,
                              std::uint32_t& terminal, const PieceVertex** vertex, int& n_vertices,
                              PieceFaces& faces) {
  ReplayedVertices alive;
  std::uint32_t at = topologies.root(sub_tet);
  for (int b = 0; b < 4; ++b) {
    const unsigned mask = alive.outside(piece, 4 + b);
    at = topologies.child(at, mask);
    if (at == ClipTopologies::kNone) return Replay::side_changed;
    if (mask == 0) continue;
    if (alive.all(mask)) {
      terminal = at;
      return Replay::clipped_away;
    }
    const ClipTopologies::Node& node = topologies.node(at);
    if (!alive.cut(piece, b, mask, topologies.bytes() + node.edges, node.n_new))
      return Replay::side_changed;
  }
  const ClipTopologies::Node& node = topologies.node(at);
  if (node.faces == ClipTopologies::kNone) return Replay::side_changed;
  const std::uint8_t* bytes = topologies.bytes() + node.faces;
  faces.count = *bytes++;
  faces.bytes = bytes;
  alive.hand_out(piece, vertex, n_vertices);
  terminal = at;
  return Replay::kept;
}

}  // namespace piece_clip
}  // namespace fdem
