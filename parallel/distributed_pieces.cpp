#include "parallel/distributed_pieces.hpp"

#include <algorithm>
#include <limits>
#include <numeric>

#include "core/error.hpp"
#include "core/types.hpp"

namespace fdem {

namespace {

struct Pair {
  std::int64_t a, b;
};
bool operator<(const Pair& x, const Pair& y) {
  return x.a != y.a ? x.a < y.a : x.b < y.b;
}
bool operator==(const Pair& x, const Pair& y) {
  return x.a == y.a && x.b == y.b;
}

// Rank r holds the ids [bounds[r], bounds[r + 1]).
class Blocks {
 public:
  Blocks(std::int64_t n, int ranks) : bounds_(static_cast<std::size_t>(ranks) + 1) {
    for (int r = 0; r <= ranks; ++r) bounds_[static_cast<std::size_t>(r)] = mul_div(n, r, ranks);
  }
  explicit Blocks(std::vector<std::int64_t> bounds) : bounds_(std::move(bounds)) {}
  int owner(std::int64_t id) const {
    return static_cast<int>(std::upper_bound(bounds_.begin(), bounds_.end(), id) -
                            bounds_.begin()) -
           1;
  }

 private:
  std::vector<std::int64_t> bounds_;
};

// Union-find whose root is the smallest index of its set.
struct UnionFind {
  std::vector<std::int64_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::int64_t find(std::int64_t i) {
    while (parent[static_cast<std::size_t>(i)] != i)
      i = parent[static_cast<std::size_t>(i)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    return i;
  }
  void unite(std::int64_t a, std::int64_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
};

// The parents of the link graph's vertices whose ids fall in this rank's block.
class Parents {
 public:
  void add(std::vector<std::int64_t> ids) {
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    id_ = std::move(ids);
    parent_ = id_;
  }
  // The parent of `id` (an id this rank does not hold is a root: its own parent).
  std::int64_t& of(std::int64_t id) {
    const auto it = std::lower_bound(id_.begin(), id_.end(), id);
    if (it == id_.end() || *it != id) {
      scratch_ = id;
      return scratch_;
    }
    return parent_[static_cast<std::size_t>(it - id_.begin())];
  }
  std::vector<std::int64_t>& parents() { return parent_; }

 private:
  std::vector<std::int64_t> id_, parent_;
  std::int64_t scratch_ = 0;
};

// The current parent of each of `ids` (any order, repeats allowed), asked of the ids' directory
// ranks.  Collective.
std::vector<std::int64_t> ask_parents(const std::vector<std::int64_t>& ids, const Blocks& directory,
                                      Parents& parents, const Communicator& comm) {
  std::vector<std::int64_t> unique = ids;
  std::sort(unique.begin(), unique.end());
  unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
  std::vector<std::vector<std::int64_t>> outbox(static_cast<std::size_t>(comm.size()));
  for (std::int64_t id : unique)
    outbox[static_cast<std::size_t>(directory.owner(id))].push_back(id);
  std::vector<int> asker;
  const std::vector<std::int64_t> asked = comm.exchange(outbox, &asker);
  std::vector<std::vector<std::int64_t>> answers(static_cast<std::size_t>(comm.size()));
  for (std::size_t i = 0; i < asked.size(); ++i)
    answers[static_cast<std::size_t>(asker[i])].push_back(parents.of(asked[i]));
  const std::vector<std::int64_t> answered = comm.exchange(answers);
  // Answers come back in rank order, each rank's in the order asked: match them to `unique`.
  std::vector<std::int64_t> parent_of_unique(unique.size());
  std::size_t next = 0;
  for (const auto& box : outbox)
    for (std::int64_t id : box) {
      const auto at = std::lower_bound(unique.begin(), unique.end(), id) - unique.begin();
      parent_of_unique[static_cast<std::size_t>(at)] = answered[next++];
    }
  std::vector<std::int64_t> out(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i)
    out[i] = parent_of_unique[static_cast<std::size_t>(
        std::lower_bound(unique.begin(), unique.end(), ids[i]) - unique.begin())];
  return out;
}

}  // namespace

std::vector<std::int32_t> distributed_pieces(const std::vector<std::int64_t>& tets,
                                             std::int64_t n_nodes, std::int64_t first_tet,
                                             const Communicator& comm, std::int32_t* n_pieces) {
  const int ranks = comm.size();
  const Blocks directory(n_nodes, ranks);
  const std::size_t n_tets = tets.size() / 4;

  // 1. Local components; each is represented by its smallest node id.
  std::vector<std::int64_t> nodes = tets;
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  const auto local = [&](std::int64_t id) {
    return static_cast<std::int64_t>(std::lower_bound(nodes.begin(), nodes.end(), id) -
                                     nodes.begin());
  };
  UnionFind components(nodes.size());
  for (std::size_t t = 0; t < n_tets; ++t)
    for (int c = 1; c < 4; ++c) components.unite(local(tets[4 * t]), local(tets[4 * t + c]));
  const auto rep = [&](std::size_t node) {
    return nodes[static_cast<std::size_t>(components.find(static_cast<std::int64_t>(node)))];
  };

  // 2. Every node to its directory with its component; components meeting at a node are linked.
  std::vector<Pair> links;
  {
    std::vector<std::vector<Pair>> outbox(static_cast<std::size_t>(ranks));
    for (std::size_t i = 0; i < nodes.size(); ++i)
      outbox[static_cast<std::size_t>(directory.owner(nodes[i]))].push_back({nodes[i], rep(i)});
    std::vector<Pair> met = comm.exchange(outbox);
    std::sort(met.begin(), met.end());
    for (std::size_t i = 1; i < met.size(); ++i)
      if (met[i].a == met[i - 1].a && met[i].b != met[i - 1].b) {
        std::size_t first = i - 1;
        while (first > 0 && met[first - 1].a == met[i].a) --first;
        links.push_back({met[first].b, met[i].b});
      }
  }

  // 3. The links' vertices get parents at their directories; rounds of hooking and jumping.
  Parents parents;
  {
    std::vector<std::vector<std::int64_t>> outbox(static_cast<std::size_t>(ranks));
    for (const Pair& l : links) {
      outbox[static_cast<std::size_t>(directory.owner(l.a))].push_back(l.a);
      outbox[static_cast<std::size_t>(directory.owner(l.b))].push_back(l.b);
    }
    parents.add(comm.exchange(outbox));
  }
  while (true) {
    // Links between the current roots (every parent is a root after the last jumps).
    std::vector<std::int64_t> ends;
    for (const Pair& l : links) ends.insert(ends.end(), {l.a, l.b});
    const std::vector<std::int64_t> roots = ask_parents(ends, directory, parents, comm);
    std::vector<Pair> contracted;
    for (std::size_t i = 0; i < links.size(); ++i)
      if (roots[2 * i] != roots[2 * i + 1])
        contracted.push_back(
            {std::min(roots[2 * i], roots[2 * i + 1]), std::max(roots[2 * i], roots[2 * i + 1])});
    std::sort(contracted.begin(), contracted.end());
    contracted.erase(std::unique(contracted.begin(), contracted.end()), contracted.end());
    links.swap(contracted);
    if (comm.sum(static_cast<std::int64_t>(links.size())) == 0) break;
    // Hook: each larger root onto the smallest root it is linked to.
    std::vector<std::vector<Pair>> hooks(static_cast<std::size_t>(ranks));
    for (const Pair& l : links)
      hooks[static_cast<std::size_t>(directory.owner(l.b))].push_back({l.b, l.a});
    for (const Pair& h : comm.exchange(hooks)) {
      std::int64_t& parent = parents.of(h.a);
      parent = std::min(parent, h.b);
    }
    // Jump until every vertex points at its root.
    while (true) {
      std::vector<std::int64_t>& mine = parents.parents();
      const std::vector<std::int64_t> grand = ask_parents(mine, directory, parents, comm);
      std::int64_t changed = 0;
      for (std::size_t i = 0; i < mine.size(); ++i)
        if (grand[i] != mine[i]) {
          mine[i] = grand[i];
          ++changed;
        }
      if (comm.sum(changed) == 0) break;
    }
  }

  // 4. Each local component's label: the root of its representative.
  std::vector<std::int64_t> reps(n_tets);
  for (std::size_t t = 0; t < n_tets; ++t)
    reps[t] = rep(static_cast<std::size_t>(local(tets[4 * t])));
  const std::vector<std::int64_t> label = ask_parents(reps, directory, parents, comm);

  // 5. Numbers: a piece's first tet, found at its label's directory, is numbered by the rank
  //    whose slice holds it.
  const std::vector<std::int64_t> counts = comm.allgather(static_cast<std::int64_t>(n_tets));
  std::vector<std::int64_t> starts(static_cast<std::size_t>(ranks) + 1, 0);
  for (int r = 0; r < ranks; ++r)
    starts[static_cast<std::size_t>(r) + 1] =
        starts[static_cast<std::size_t>(r)] + counts[static_cast<std::size_t>(r)];
  const Blocks slices(starts);
  std::vector<Pair> firsts;  // (label, first local tet's global index)
  for (std::size_t t = 0; t < n_tets; ++t)
    firsts.push_back({label[t], first_tet + std::int64_t(t)});
  std::sort(firsts.begin(), firsts.end());
  firsts.erase(std::unique(firsts.begin(), firsts.end(),
                           [](const Pair& x, const Pair& y) { return x.a == y.a; }),
               firsts.end());
  std::vector<std::vector<Pair>> outbox(static_cast<std::size_t>(ranks));
  for (const Pair& f : firsts) outbox[static_cast<std::size_t>(directory.owner(f.a))].push_back(f);
  std::vector<int> asker;
  std::vector<Pair> seen = comm.exchange(outbox, &asker);
  std::vector<Pair> at_directory = seen;  // (label, first tet) over all ranks
  std::sort(at_directory.begin(), at_directory.end());
  at_directory.erase(std::unique(at_directory.begin(), at_directory.end(),
                                 [](const Pair& x, const Pair& y) { return x.a == y.a; }),
                     at_directory.end());
  outbox.assign(static_cast<std::size_t>(ranks), {});
  for (const Pair& f : at_directory)
    outbox[static_cast<std::size_t>(slices.owner(f.b))].push_back({f.b, f.a});
  std::vector<Pair> mine = comm.exchange(outbox);  // (first tet, label) of pieces starting here
  std::sort(mine.begin(), mine.end());
  const std::vector<std::int64_t> piece_counts =
      comm.allgather(static_cast<std::int64_t>(mine.size()));
  const std::int64_t base =
      std::accumulate(piece_counts.begin(), piece_counts.begin() + comm.rank(), std::int64_t{0});
  const std::int64_t total =
      std::accumulate(piece_counts.begin(), piece_counts.end(), std::int64_t{0});
  FDEM_VERIFY(total <= std::numeric_limits<std::int32_t>::max(), "piece count fits 32 bits");
  outbox.assign(static_cast<std::size_t>(ranks), {});
  for (std::size_t i = 0; i < mine.size(); ++i)
    outbox[static_cast<std::size_t>(directory.owner(mine[i].b))].push_back(
        {mine[i].b, base + static_cast<std::int64_t>(i)});
  std::vector<Pair> numbered = comm.exchange(outbox);  // (label, piece)
  std::sort(numbered.begin(), numbered.end());
  outbox.assign(static_cast<std::size_t>(ranks), {});
  for (std::size_t i = 0; i < seen.size(); ++i) {
    const auto it = std::lower_bound(numbered.begin(), numbered.end(),
                                     Pair{seen[i].a, std::numeric_limits<std::int64_t>::min()});
    FDEM_VERIFY(it != numbered.end() && it->a == seen[i].a, "every piece is numbered");
    outbox[static_cast<std::size_t>(asker[i])].push_back(*it);
  }
  std::vector<Pair> answers = comm.exchange(outbox);  // (label, piece) of this rank's labels
  std::sort(answers.begin(), answers.end());
  std::vector<std::int32_t> piece(n_tets);
  for (std::size_t t = 0; t < n_tets; ++t) {
    const auto it = std::lower_bound(answers.begin(), answers.end(),
                                     Pair{label[t], std::numeric_limits<std::int64_t>::min()});
    FDEM_VERIFY(it != answers.end() && it->a == label[t], "a local tet's piece is known");
    piece[t] = static_cast<std::int32_t>(it->b);
  }
  if (n_pieces) *n_pieces = static_cast<std::int32_t>(total);
  return piece;
}

}  // namespace fdem
