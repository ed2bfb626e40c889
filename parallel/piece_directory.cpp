#include "parallel/piece_directory.hpp"

#include <mpi.h>

#include <algorithm>
#include <map>
#include <numeric>

#include "core/error.hpp"
#include "core/model_builder.hpp"
#include "parallel/gid_blocks.hpp"

namespace fdem {

namespace {

GidBlocks piece_blocks(const PieceTable& pieces, const Communicator& comm) {
  return GidBlocks{static_cast<std::int64_t>(pieces.size()), comm.size()};
}

std::size_t slot_of(const std::vector<std::int32_t>& sorted_ids, std::int32_t piece) {
  const auto it = std::lower_bound(sorted_ids.begin(), sorted_ids.end(), piece);
  FDEM_VERIFY(it != sorted_ids.end() && *it == piece, "a piece of this rank");
  return static_cast<std::size_t>(it - sorted_ids.begin());
}

// A holder's neighbours in the chain of ranks holding tets of `piece` (−1 at the ends).
struct ChainLink {
  std::int32_t piece, previous, next;
};

// Running or finished sums of a piece: Σ m and Σ m·c, or the mass and centroid.
struct PieceSums {
  std::int32_t piece, padding;
  double mass, moment[3];
};

// The running sums of the pieces in `slots`, as one message per neighbouring rank.
std::vector<double> pack_running(const std::vector<PieceInfo>& running,
                                 const std::vector<std::size_t>& slots) {
  std::vector<double> out;
  out.reserve(4 * slots.size());
  for (const std::size_t s : slots) {
    out.push_back(running[s].mass);
    for (int k = 0; k < 3; ++k) out.push_back(running[s].centroid0[k]);
  }
  return out;
}

// Passes the running sums of the local pieces along their chains: waits for the previous
// holders (lower ranks), adds this block's tets in gid order, sends to the next holders.  Ranks
// wait only on lower ranks, so the chain cannot deadlock.
std::vector<PieceInfo> chain_piece_sums(const Model& model, const std::vector<std::int32_t>& local,
                                        const std::vector<ChainLink>& chain,
                                        const Communicator& comm) {
  constexpr int tag = 53;
  std::map<int, std::vector<std::size_t>> from, to;  // neighbour rank → slots, ascending id
  for (std::size_t i = 0; i < chain.size(); ++i) {
    if (chain[i].previous >= 0) from[chain[i].previous].push_back(i);
    if (chain[i].next >= 0) to[chain[i].next].push_back(i);
  }
  std::vector<PieceInfo> running(local.size());
  std::vector<std::vector<double>> inbox;
  inbox.reserve(from.size());
  std::vector<MPI_Request> requests(from.size());
  for (const auto& [rank, slots] : from) {
    inbox.emplace_back(4 * slots.size());
    MPI_Irecv(inbox.back().data(), detail::checked_count(inbox.back().size(), 1), MPI_DOUBLE, rank,
              tag, comm.handle(), &requests[inbox.size() - 1]);
  }
  MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  std::size_t box = 0;
  for (const auto& [rank, slots] : from) {
    const std::vector<double>& values = inbox[box++];
    for (std::size_t j = 0; j < slots.size(); ++j) {
      running[slots[j]].mass = values[4 * j];
      running[slots[j]].centroid0 = Vec3(values[4 * j + 1], values[4 * j + 2], values[4 * j + 3]);
    }
  }
  const TetArrays& tets = model.tets;
  for (LocalIndex t = 0; t < tets.size(); ++t) {
    Vec3 X[4];
    for (int c = 0; c < 4; ++c) X[c] = vec3_at(model.nodes.x0.data(), tets.nodes[4 * t + c]);
    add_to_piece(running[slot_of(local, tets.piece[t])],
                 model.materials[tets.material[t]].density * tets.volume0[t], X);
  }
  std::vector<std::vector<double>> outbox;
  outbox.reserve(to.size());
  requests.assign(to.size(), MPI_REQUEST_NULL);
  for (const auto& [rank, slots] : to) {
    outbox.push_back(pack_running(running, slots));
    MPI_Isend(outbox.back().data(), detail::checked_count(outbox.back().size(), 1), MPI_DOUBLE,
              rank, tag, comm.handle(), &requests[outbox.size() - 1]);
  }
  MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  return running;
}

// Records of `words` as [piece, sums...] from the ranks in `source` (one per word), merged into
// `block` (one per piece of the directory block starting at `first`).  Returns (piece, sender).
template <class Sums>
std::vector<std::pair<std::int32_t, int>> merge_at_directory(const std::vector<std::int64_t>& words,
                                                             const std::vector<int>& source,
                                                             std::int32_t first,
                                                             std::vector<Sums>& block) {
  std::vector<std::pair<std::int32_t, int>> senders;
  const std::int64_t* w = words.data();
  const std::int64_t* const end = w + words.size();
  while (w < end) {
    const int from = source[static_cast<std::size_t>(w - words.data())];
    const std::int64_t piece = *w++;
    FDEM_VERIFY(piece >= first && piece < first + static_cast<std::int64_t>(block.size()),
                "a piece of the directory block");
    block[static_cast<std::size_t>(piece - first)].add(Sums::from_words(w));
    senders.emplace_back(static_cast<std::int32_t>(piece), from);
  }
  return senders;
}

// Per owned piece, [piece, sums...] to its directory rank.
template <class Sums>
std::vector<std::vector<std::int64_t>> pack_for_directory(const std::vector<std::int32_t>& ids,
                                                          const std::vector<Sums>& sums,
                                                          const GidBlocks& blocks) {
  std::vector<std::vector<std::int64_t>> outbox(static_cast<std::size_t>(blocks.ranks));
  for (std::size_t i = 0; i < ids.size(); ++i) {
    std::vector<std::int64_t>& box = outbox[static_cast<std::size_t>(blocks.owner(ids[i]))];
    box.push_back(ids[i]);
    sums[i].append_words(box);
  }
  return outbox;
}

// A piece's centres as the directory sends them back to the ranks holding its nodes.
struct CentreRow {
  std::int32_t piece, padding;
  double centroid[3], reference[3];
};

}  // namespace

PieceBlock piece_directory_block(const PieceTable& pieces, const Communicator& comm) {
  const GidBlocks blocks = piece_blocks(pieces, comm);
  return {static_cast<std::int32_t>(blocks.begin(comm.rank())),
          static_cast<std::int32_t>(blocks.begin(comm.rank() + 1))};
}

void keep_directory_block(PieceTable& pieces, const Communicator& comm) {
  const PieceBlock block = piece_directory_block(pieces, comm);
  pieces.keep_only_range(block.begin, block.end);
}

void sum_pieces_by_directory(Model& model, const Communicator& comm) {
  const std::size_t ranks = static_cast<std::size_t>(comm.size());
  PieceTable& pieces = model.pieces;
  const GidBlocks blocks = piece_blocks(pieces, comm);
  const PieceBlock block = piece_directory_block(pieces, comm);
  std::vector<std::int32_t> local(model.tets.piece.begin(), model.tets.piece.end());
  std::sort(local.begin(), local.end());
  local.erase(std::unique(local.begin(), local.end()), local.end());

  // The directory learns who holds tets of each piece (they arrive in rank order) and tells each
  // holder its neighbours in that order.
  std::vector<std::vector<std::int32_t>> held(ranks);
  for (const std::int32_t p : local) held[static_cast<std::size_t>(blocks.owner(p))].push_back(p);
  std::vector<int> holder;
  const std::vector<std::int32_t> holds = comm.exchange(held, &holder);
  std::vector<std::size_t> order(holds.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return holds[a] < holds[b]; });
  std::vector<std::vector<ChainLink>> links(ranks);
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::int32_t p = holds[order[i]];
    const bool first = i == 0 || holds[order[i - 1]] != p;
    const bool last = i + 1 == order.size() || holds[order[i + 1]] != p;
    links[static_cast<std::size_t>(holder[order[i]])].push_back(
        {p, first ? -1 : holder[order[i - 1]], last ? -1 : holder[order[i + 1]]});
  }
  const std::vector<ChainLink> chain = comm.exchange(links);  // ascending piece, as `local`
  FDEM_VERIFY(chain.size() == local.size(), "one chain link per local piece");
  for (std::size_t i = 0; i < chain.size(); ++i)
    FDEM_VERIFY(chain[i].piece == local[i], "chain links in ascending piece order");

  const std::vector<PieceInfo> running = chain_piece_sums(model, local, chain, comm);

  // The last holder's sums are the serial ones: finished at the directory, sent to every holder.
  std::vector<std::vector<PieceSums>> finals(ranks);
  for (std::size_t i = 0; i < local.size(); ++i)
    if (chain[i].next < 0) {
      const Vec3& m = running[i].centroid0;
      finals[static_cast<std::size_t>(blocks.owner(local[i]))].push_back(
          {local[i], 0, running[i].mass, {m.x(), m.y(), m.z()}});
    }
  pieces.keep_range(block.begin, block.end);
  std::int64_t finished = 0;
  for (const PieceSums& f : comm.exchange(finals)) {
    PieceInfo& info = pieces[f.piece];
    info.mass = f.mass;
    info.centroid0 = Vec3(f.moment[0], f.moment[1], f.moment[2]);
    finish_piece(info);
    ++finished;
  }
  FDEM_VERIFY(finished == block.end - block.begin, "every piece of the block has tets");
  std::vector<std::vector<PieceSums>> answers(ranks);
  for (const std::size_t i : order) {
    const PieceInfo& info = pieces[holds[i]];
    answers[static_cast<std::size_t>(holder[i])].push_back(
        {holds[i], 0, info.mass, {info.centroid0.x(), info.centroid0.y(), info.centroid0.z()}});
  }
  const std::vector<PieceSums> mine = comm.exchange(answers);
  pieces.keep(local);
  for (const PieceSums& a : mine) {
    PieceInfo& info = pieces[a.piece];
    info.mass = a.mass;
    info.centroid0 = Vec3(a.moment[0], a.moment[1], a.moment[2]);
  }
}

BlockMotions directory_piece_motions(const Model& model, const Communicator& comm) {
  const GidBlocks blocks = piece_blocks(model.pieces, comm);
  const PieceBlock block = piece_directory_block(model.pieces, comm);
  const std::size_t n_block = static_cast<std::size_t>(block.end - block.begin);
  const OwnedPieces owned = owned_pieces(model.nodes);

  // The moments of the owned nodes to the directory, which merges them into the centres.
  std::vector<int> source;
  std::vector<std::int64_t> words = comm.exchange(
      pack_for_directory(owned.ids, piece_moments(model.nodes, owned), blocks), &source);
  std::vector<PieceMoments> block_moments(n_block);
  const std::vector<std::pair<std::int32_t, int>> senders =
      merge_at_directory(words, source, block.begin, block_moments);
  std::vector<PieceCentres> block_centres;
  block_centres.reserve(n_block);
  for (const PieceMoments& m : block_moments) block_centres.push_back(centres_of(m));

  // The centres back to the ranks that sent moments; their spreads about them to the directory.
  std::vector<std::vector<CentreRow>> answers(static_cast<std::size_t>(comm.size()));
  for (const auto& [piece, rank] : senders) {
    const PieceCentres& c = block_centres[static_cast<std::size_t>(piece - block.begin)];
    answers[static_cast<std::size_t>(rank)].push_back(
        {piece,
         0,
         {c.centroid.x(), c.centroid.y(), c.centroid.z()},
         {c.reference.x(), c.reference.y(), c.reference.z()}});
  }
  const std::vector<CentreRow> rows = comm.exchange(answers);
  FDEM_VERIFY(rows.size() == owned.ids.size(), "the centres of every owned piece come back");
  std::vector<PieceCentres> centres(owned.ids.size());
  for (const CentreRow& r : rows) {
    PieceCentres& c = centres[slot_of(owned.ids, r.piece)];
    c.centroid = Vec3(r.centroid[0], r.centroid[1], r.centroid[2]);
    c.reference = Vec3(r.reference[0], r.reference[1], r.reference[2]);
  }
  words = comm.exchange(
      pack_for_directory(owned.ids, piece_spreads(model.nodes, owned, centres), blocks), &source);
  std::vector<PieceSpread> block_spreads(n_block);
  merge_at_directory(words, source, block.begin, block_spreads);

  BlockMotions out;
  out.first = block.begin;
  out.motion.resize(n_block);
  for (std::size_t i = 0; i < n_block; ++i)
    out.motion[i] = {block_centres[i].centroid, block_centres[i].velocity,
                     rotation_of(block_spreads[i])};
  return out;
}

}  // namespace fdem
