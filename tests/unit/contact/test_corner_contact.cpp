#include <catch2/catch.hpp>
#include <random>

#include "../core/kuhn_boxes.hpp"
#include "contact/contact_stage.hpp"
#include "contact/corner_contact.hpp"
#include "contact/potential_contact_kernels.hpp"

using namespace fdem;

namespace {

TetGeometry geometry_of(const Model& model, LocalIndex t) {
  TetGeometry g;
  compute_tet_geometry(tet_corners(model, t), g);
  return g;
}

// A lone tet as corner contact sees it: all faces on its surface, all edges folds, its current
// shape as reference.
CornerTet lone_tet(const TetCorners& x, GlobalId first_gid) {
  CornerTet c;
  c.faces = 0xFFFFu;  // surface faces and fold edges; no fold vertex: nothing near a vertex
  for (int k = 0; k < 4; ++k) c.node_gid[k] = first_gid + k;
  Vec3 gradient[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  double det = 0.0;
  REQUIRE(barycentric_gradients(x, gradient, det));
  for (int f = 0; f < 4; ++f) {
    c.inverse_height0[f] = gradient[f].norm();
    c.area0[f] = 3.0 * std::abs(det) / 6.0 * c.inverse_height0[f];
  }
  return c;
}

// How many surface faces facing n (n·n_T < −½) of `model`'s tets in [first, last) hold p.
int claims(const Model& model, LocalIndex first, LocalIndex last, const Vec3& p, const Vec3& n) {
  int count = 0;
  for (LocalIndex t = first; t < last; ++t) {
    const TetGeometry g = geometry_of(model, t);
    const CornerTet c = corner_tet(model, t);
    for (int f = 0; f < 4; ++f)
      if ((c.faces & contact_face_bits::surface(f)) && n.dot(-g.inward_normal[f]) < -0.5 &&
          corner_over_face(p, n, kFoldTolerance * 0.25, g, c, f))
        ++count;
  }
  return count;
}

}  // namespace

TEST_CASE("corner contact: one face of a flat patch holds a corner, on its vertices and edges too",
          "[corner_contact]") {
  // The top of a 4 × 4-cell box, z = 0, cells of 0.25 m.
  const Model model = test::kuhn_boxes_model({{Vec3(0, 0, -0.25), {4, 4, 1}, 0.25}});
  const LocalIndex n_tets = model.tets.size();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> tilt(-0.2, 0.2), inside(0.005, 0.995);
  for (const Vec3& n : {Vec3(0, 0, -1), Vec3(0.05, -0.1, -1).normalized(),
                        Vec3(tilt(random), tilt(random), -1).normalized()}) {
    INFO("seen along " << n.transpose());
    // Every vertex, edge midpoint and cell centre of the patch's inside, exactly, below it.
    for (int i = 1; i < 16; ++i)
      for (int j = 1; j < 16; ++j) {
        const Vec3 p(0.0625 * i, 0.0625 * j, -1e-3);
        INFO("p " << p.transpose());
        CHECK(claims(model, 0, n_tets, p, n) == 1);
      }
    for (int k = 0; k < 200; ++k) {
      const Vec3 p(inside(random), inside(random), -2e-3);
      INFO("p " << p.transpose());
      CHECK(claims(model, 0, n_tets, p, n) == 1);
    }
  }
  // Beside the box's edges (folds), on them and up to 2 % of a cell edge outside: one face, at
  // the vertices along them too (each vertex's zone has one owner); then none.
  for (const Vec3& n : {Vec3(0, 0, -1), Vec3(0.05, -0.1, -1).normalized()}) {
    INFO("seen along " << n.transpose());
    for (const double beyond : {0.0, 1e-9, 1e-4, 0.015 * 0.25})
      for (int j = 0; j <= 16; ++j) {
        const double along = 0.0625 * j;
        for (const Vec3& p : {Vec3(1.0 + beyond, along, -1e-3), Vec3(-beyond, along, -1e-3),
                              Vec3(along, 1.0 + beyond, -1e-3), Vec3(along, -beyond, -1e-3)}) {
          INFO("p " << p.transpose());
          CHECK(claims(model, 0, n_tets, p, n) == 1);
        }
      }
    // Beyond the box's corner in both directions, by less than the vertex zone: its owner.
    CHECK(claims(model, 0, n_tets, Vec3(1.001, 1.001, -1e-3), n) == 1);
    CHECK(claims(model, 0, n_tets, Vec3(-0.001, 1.002, -1e-3), n) == 1);
  }
  const Vec3 down(0, 0, -1);
  CHECK(claims(model, 0, n_tets, Vec3(1.0 + 0.03 * 0.25, 0.3, -1e-3), down) == 0);
  CHECK(claims(model, 0, n_tets, Vec3(1.01, 1.01, -1e-3), down) == 0);
}

TEST_CASE("corner contact: the forces are the exact gradient of the energy", "[corner_contact]") {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> tilt(-0.05, 0.05), shift(-2e-3, 2e-3);
  const double penalty = 1e10;
  TetCorners target;
  target.x[0] = Vec3(0, 0, 0);
  target.x[1] = Vec3(1, 0, 0);
  target.x[2] = Vec3(0, 1, 0);
  target.x[3] = Vec3(0.3, 0.3, -0.8);
  const CornerTet corner_target = lone_tet(target, 10);
  int pressed = 0;
  for (int trial = 0; trial < 100; ++trial) {
    // A small tet whose bottom face dips ~1 mm into the target's top face, turned a little.
    TetCorners c;
    c.x[0] = Vec3(0.25, 0.25, 0);
    c.x[1] = Vec3(0.45, 0.25, 0);
    c.x[2] = Vec3(0.25, 0.45, 0);
    c.x[3] = Vec3(0.3, 0.3, 0.3);
    const CornerTet corner_c = lone_tet(c, 20);
    const Eigen::Matrix3d turn = (Eigen::AngleAxisd(tilt(random), Vec3::UnitX()) *
                                  Eigen::AngleAxisd(tilt(random), Vec3::UnitY()))
                                     .toRotationMatrix();
    const Vec3 offset(shift(random), shift(random), -1e-3 + shift(random));
    for (Vec3& x : c.x) x = turn * (x - Vec3(0.3, 0.3, 0)) + Vec3(0.3, 0.3, 0) + offset;
    const auto result = [&](const TetCorners& a, const TetCorners& b) {
      TetGeometry ga, gb;
      compute_tet_geometry(a, ga);
      compute_tet_geometry(b, gb);
      return corner_contact(ga, corner_c, gb, corner_target, penalty);
    };
    const ContactPairResult r = result(c, target);
    if (!r.overlapping) continue;
    ++pressed;
    const double largest = largest_nodal_force(r);
    const double h = 1e-9;
    for (int side = 0; side < 2; ++side)
      for (int v = 0; v < 4; ++v)
        for (int k = 0; k < 3; ++k) {
          TetCorners plus_c = c, minus_c = c, plus_t = target, minus_t = target;
          (side == 0 ? plus_c : plus_t).x[v][k] += h;
          (side == 0 ? minus_c : minus_t).x[v][k] -= h;
          const double derivative =
              (result(plus_c, plus_t).energy - result(minus_c, minus_t).energy) / (2 * h);
          const double force = (side == 0 ? r.force_contactor : r.force_target)[v][k];
          INFO("trial " << trial << " side " << side << " corner " << v << " axis " << k);
          CHECK(std::abs(force + derivative) <= 1e-5 * largest);
        }
    // Equal and opposite: the pair's forces sum to zero.
    Vec3 sum = Vec3::Zero();
    for (int v = 0; v < 4; ++v) sum += r.force_contactor[v] + r.force_target[v];
    CHECK(sum.norm() <= 1e-12 * largest);
  }
  CHECK(pressed > 80);
}

TEST_CASE("corner contact: a joint pressed face on face has potential contact's stiffness",
          "[corner_contact]") {
  // Two boxes of 2 × 2 × 1 cells of 0.5 m on one another; the upper one pressed down by d.
  Model model =
      test::kuhn_boxes_model({{Vec3(0, 0, -0.5), {2, 2, 1}, 0.5}, {Vec3(0, 0, 0), {2, 2, 1}, 0.5}});
  const LocalIndex per_box = model.tets.size() / 2;
  const double d = 1e-6, penalty = 1e10;
  for (LocalIndex t = per_box; t < model.tets.size(); ++t)
    for (int c = 0; c < 4; ++c) {
      const LocalIndex node = model.tets.nodes[4 * t + c];
      model.nodes.x[3 * node + 2] = model.nodes.x0(node).z() - d;
    }
  double corner_force = 0.0, potential_force = 0.0;
  for (LocalIndex a = per_box; a < model.tets.size(); ++a)
    for (LocalIndex b = 0; b < per_box; ++b) {
      const TetGeometry ga = geometry_of(model, a), gb = geometry_of(model, b);
      const ContactPairResult corner =
          corner_contact(ga, corner_tet(model, a), gb, corner_tet(model, b), penalty);
      const ContactPairResult potential =
          potential_contact(tet_corners(model, a), tet_corners(model, b), penalty);
      for (int c = 0; c < 4; ++c) {
        corner_force += corner.force_contactor[c].z();
        potential_force += potential.force_contactor[c].z();
      }
    }
  // Per area 4p(1/H + 1/H) d with H = 0.5 m the tets' altitude over the joint, on 1 m².
  const double expected = 4 * penalty * (2 / 0.5) * 1.0 * d;
  CHECK(corner_force == Approx(expected).epsilon(1e-9));
  CHECK(potential_force == Approx(expected).epsilon(1e-4));
}

TEST_CASE("corner contact: a pair whose faces face no other stays so for its apart travel",
          "[corner_contact]") {
  // Random lone tets turned at random: where no face of one faces a face of the other, every
  // move of their corners by at most the apart travel in all (split at random between the two,
  // each corner in a random direction) keeps every pair of faces apart (n_s·n_t ≥ −½), so the
  // kernel gives nothing; where some pair faces, the travel is 0.
  std::mt19937 random(11);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0), share(0.0, 1.0);
  const auto random_tet = [&](const Vec3& centre) {
    for (;;) {
      TetCorners x;
      for (int c = 0; c < 4; ++c)
        x.x[c] = centre + 0.1 * Vec3(coordinate(random), coordinate(random), coordinate(random));
      TetGeometry g;
      compute_tet_geometry(x, g);
      if (g.valid && std::abs(g.edge_det) > 1e-5) return x;
    }
  };
  const auto least_margin = [](const TetGeometry& a, const TetGeometry& b) {
    double margin = 1e9;
    for (int s = 0; s < 4; ++s)
      for (int t = 0; t < 4; ++t)
        margin = std::min(margin, a.inward_normal[s].dot(b.inward_normal[t]) + 0.5);
    return margin;
  };
  int apart = 0, facing = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const TetCorners xa = random_tet(Vec3::Zero()), xb = random_tet(Vec3(0.15, 0, 0));
    TetGeometry a, b;
    compute_tet_geometry(xa, a);
    compute_tet_geometry(xb, b);
    const CornerTet ca = lone_tet(xa, 0), cb = lone_tet(xb, 4);
    const double travel = corner_pair_apart_travel(a, ca, b, cb);
    if (least_margin(a, b) <= 1e-12) {
      ++facing;
      CHECK(travel == 0.0);
      continue;
    }
    ++apart;
    REQUIRE(travel > 0.0);
    for (int move = 0; move < 20; ++move) {
      const double to_a = travel * share(random);
      TetCorners ya = xa, yb = xb;
      for (int c = 0; c < 4; ++c) {
        const Vec3 da(coordinate(random), coordinate(random), coordinate(random));
        const Vec3 db(coordinate(random), coordinate(random), coordinate(random));
        ya.x[c] += to_a * share(random) * da.normalized();
        yb.x[c] += (travel - to_a) * share(random) * db.normalized();
      }
      TetGeometry a2, b2;
      compute_tet_geometry(ya, a2);
      compute_tet_geometry(yb, b2);
      INFO("trial " << trial << ", travel " << travel);
      CHECK(least_margin(a2, b2) > 0.0);
      CHECK_FALSE(corner_contact(a2, ca, b2, cb, 1e9).overlapping);
    }
  }
  CHECK(apart > 100);  // both kinds of pairs are common among random tets
  CHECK(facing > 100);
  // A tet without surface faces never meets anything: unbounded.
  TetGeometry a, b;
  const TetCorners xa = random_tet(Vec3::Zero()), xb = random_tet(Vec3(0.05, 0, 0));
  compute_tet_geometry(xa, a);
  compute_tet_geometry(xb, b);
  CornerTet inner = lone_tet(xa, 0);
  inner.faces = 0;
  CHECK(corner_pair_apart_travel(a, inner, b, lone_tet(xb, 4)) == kUnboundedTravel);
}
