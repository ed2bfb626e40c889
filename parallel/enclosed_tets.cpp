#include "parallel/enclosed_tets.hpp"

#include <algorithm>

#include "core/error.hpp"
#include "parallel/directory_hash.hpp"

namespace fdem {

namespace {

bool node_less(const BoundaryMeshNode& p, const BoundaryMeshNode& q) {
  return p.body != q.body ? p.body < q.body : p.node < q.node;
}
bool node_equal(const BoundaryMeshNode& p, const BoundaryMeshNode& q) {
  return p.body == q.body && p.node == q.node;
}
int node_rank(const BoundaryMeshNode& n, int ranks) {
  return directory_rank({n.body, n.node}, ranks);
}
void sort_unique(std::vector<BoundaryMeshNode>& nodes) {
  std::sort(nodes.begin(), nodes.end(), node_less);
  nodes.erase(std::unique(nodes.begin(), nodes.end(), node_equal), nodes.end());
}

}  // namespace

std::vector<std::uint8_t> enclosed_face_tets(std::vector<BoundaryMeshNode> boundary,
                                             const std::vector<FaceTet>& face_tets,
                                             const std::vector<char>& jointed,
                                             const Communicator& comm) {
  const int ranks = comm.size();
  // 1  The node directory: every boundary mesh node at the rank of its hash.
  std::vector<BoundaryMeshNode> directory;
  {
    sort_unique(boundary);
    std::vector<std::vector<BoundaryMeshNode>> outbox(static_cast<std::size_t>(ranks));
    for (const BoundaryMeshNode& n : boundary)
      outbox[static_cast<std::size_t>(node_rank(n, ranks))].push_back(n);
    release(boundary);
    directory = comm.exchange(outbox);
    sort_unique(directory);
  }
  // 2  The corners of this rank's jointed tets, each once, asked of their directory ranks.
  std::vector<BoundaryMeshNode> corners;
  for (const FaceTet& t : face_tets)
    if (jointed[static_cast<std::size_t>(t.body)])
      for (int c = 0; c < 4; ++c) corners.push_back({t.body, t.mesh_node[c]});
  sort_unique(corners);
  std::vector<std::vector<BoundaryMeshNode>> questions(static_cast<std::size_t>(ranks));
  for (const BoundaryMeshNode& n : corners)
    questions[static_cast<std::size_t>(node_rank(n, ranks))].push_back(n);
  std::vector<int> asker;
  const std::vector<BoundaryMeshNode> asked = comm.exchange(questions, &asker);
  // 3  Answers: the boundary nodes among them, back to who asked.
  std::vector<std::vector<BoundaryMeshNode>> answers(static_cast<std::size_t>(ranks));
  for (std::size_t i = 0; i < asked.size(); ++i)
    if (std::binary_search(directory.begin(), directory.end(), asked[i], node_less))
      answers[static_cast<std::size_t>(asker[i])].push_back(asked[i]);
  std::vector<BoundaryMeshNode> on_boundary = comm.exchange(answers);
  sort_unique(on_boundary);
  std::vector<std::uint8_t> enclosed(face_tets.size(), 0);
  for (std::size_t i = 0; i < face_tets.size(); ++i) {
    const FaceTet& t = face_tets[i];
    if (!jointed[static_cast<std::size_t>(t.body)]) continue;
    bool inside = true;
    for (int c = 0; c < 4 && inside; ++c)
      inside = !std::binary_search(on_boundary.begin(), on_boundary.end(),
                                   BoundaryMeshNode{t.body, t.mesh_node[c]}, node_less);
    enclosed[i] = inside ? 1 : 0;
  }
  return enclosed;
}

}  // namespace fdem
