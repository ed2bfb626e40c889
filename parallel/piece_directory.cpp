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
    for (int c = 0; c < 4; ++c) X[c] = model.nodes.x0(tets.nodes[4 * t + c]);
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

// Per owned piece, [piece, sums...] to its directory rank; make(i) gives the sums of
// owned.ids[i], made one piece at a time.
template <class MakeSums>
std::vector<std::vector<std::int64_t>> pack_for_directory(const OwnedPieces& owned,
                                                          const GidBlocks& blocks,
                                                          const MakeSums& make) {
  std::vector<std::vector<std::int64_t>> outbox(static_cast<std::size_t>(blocks.ranks));
  for (std::size_t i = 0; i < owned.ids.size(); ++i) {
    std::vector<std::int64_t>& box = outbox[static_cast<std::size_t>(blocks.owner(owned.ids[i]))];
    box.push_back(owned.ids[i]);
    make(i).append_words(box);
  }
  return outbox;
}

// The records [piece, sums...] of `words` (sent by the ranks in `source`, one per word), merged
// piece by piece: use(piece, merged sums, ranks that sent them) in ascending piece.  Only one
// piece's merged sums exist at a time.
template <class Sums, class Use>
void merge_by_piece(const std::vector<std::int64_t>& words, const std::vector<int>& source,
                    const Use& use) {
  struct Record {
    std::int64_t piece;
    std::size_t at;  // word of its sums
    int from;
  };
  std::vector<Record> records;
  const std::int64_t* w = words.data();
  const std::int64_t* const end = w + words.size();
  while (w < end) {
    const std::size_t at = static_cast<std::size_t>(w - words.data());
    const std::int64_t piece = *w++;
    records.push_back({piece, at + 1, source[at]});
    Sums::from_words(w);  // moves past them
  }
  std::stable_sort(records.begin(), records.end(),
                   [](const Record& a, const Record& b) { return a.piece < b.piece; });
  std::vector<int> senders;
  for (std::size_t i = 0; i < records.size();) {
    Sums merged;
    senders.clear();
    const std::int64_t piece = records[i].piece;
    for (; i < records.size() && records[i].piece == piece; ++i) {
      const std::int64_t* sums = words.data() + records[i].at;
      merged.add(Sums::from_words(sums));
      senders.push_back(records[i].from);
    }
    use(static_cast<std::int32_t>(piece), merged, senders);
  }
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
  const NodeArrays& nodes = model.nodes;
  const OwnedPieces owned = owned_pieces(nodes);
  BlockMotions out;
  out.first = block.begin;
  out.motion.resize(static_cast<std::size_t>(block.end - block.begin));
  const auto in_block = [&](std::int32_t piece) -> PieceMotion& {
    FDEM_VERIFY(piece >= block.begin && piece < block.end, "a piece of the directory block");
    return out.motion[static_cast<std::size_t>(piece - block.begin)];
  };

  // The moments of the owned nodes to the directory, which merges them into the centres and
  // sends those back to the ranks that sent moments.
  std::vector<int> source;
  std::vector<std::int64_t> words = comm.exchange(
      pack_for_directory(owned, blocks,
                         [&](std::size_t i) { return piece_moments(nodes, owned, i); }),
      &source);
  std::vector<std::vector<CentreRow>> answers(static_cast<std::size_t>(comm.size()));
  std::int64_t merged_pieces = 0;
  merge_by_piece<PieceMoments>(
      words, source,
      [&](std::int32_t piece, const PieceMoments& moments, const std::vector<int>& senders) {
        const PieceCentres c = centres_of(moments);
        in_block(piece).centroid = c.centroid;
        in_block(piece).velocity = c.velocity;
        for (const int rank : senders)
          answers[static_cast<std::size_t>(rank)].push_back(
              {piece,
               0,
               {c.centroid.x(), c.centroid.y(), c.centroid.z()},
               {c.reference.x(), c.reference.y(), c.reference.z()}});
        ++merged_pieces;
      });
  FDEM_VERIFY(merged_pieces == block.end - block.begin, "every piece of the block has nodes");
  const std::vector<CentreRow> rows = comm.exchange(answers);
  release(answers);
  FDEM_VERIFY(rows.size() == owned.ids.size(), "the centres of every owned piece come back");
  std::vector<PieceCentres> centres(owned.ids.size());
  for (const CentreRow& r : rows) {
    PieceCentres& c = centres[slot_of(owned.ids, r.piece)];
    c.centroid = Vec3(r.centroid[0], r.centroid[1], r.centroid[2]);
    c.reference = Vec3(r.reference[0], r.reference[1], r.reference[2]);
  }

  // The spreads about the centres to the directory: the rotations.
  words = comm.exchange(
      pack_for_directory(owned, blocks,
                         [&](std::size_t i) { return piece_spread(nodes, owned, i, centres[i]); }),
      &source);
  merge_by_piece<PieceSpread>(
      words, source, [&](std::int32_t piece, const PieceSpread& spread, const std::vector<int>&) {
        in_block(piece).rotation = rotation_of(spread);
      });
  return out;
}

}  // namespace fdem
