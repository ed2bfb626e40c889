// Central-difference check of the nodal-contact kernel of prototype.patch
// (contact/nodal_contact.hpp once the patch is applied), from the repository root:
//   g++ -O2 -std=c++17 -I. -I/usr/include/eigen3 \
//       benchmarks/experiments/nodal_contact/gradient_check.cpp -o /tmp/gradient_check
// A tet pressed 0.02 m into another through a face, corners jittered by up to 0.01 m; every face
// a surface face, every claim accepted (the selection held fixed): the largest difference between
// a nodal force and −∂U/∂x by central differences (h = 1e-7 m), over the pair's largest force.
#include <algorithm>
#include <cstdio>
#include <random>

#include "contact/nodal_contact.hpp"

using namespace fdem;

namespace {
NodalTetFaces all_surface(const TetCorners& t) {
  NodalTetFaces faces;
  TetGeometry g;
  compute_tet_geometry(t, g);
  for (int f = 0; f < 4; ++f) {
    int w[3];
    nodal_face_corners(f, w);
    faces.area0[f] = 0.5 * (t.x[w[1]] - t.x[w[0]]).cross(t.x[w[2]] - t.x[w[0]]).norm();
    faces.height0[f] = 1.0 / g.gradient[f].norm();
  }
  faces.surface = 0xF;
  faces.fold_edges = 0xFFF;
  return faces;
}
}  // namespace

int main() {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  TetCorners upper, lower;
  upper.x[0] = Vec3(0, 0, 0), upper.x[1] = Vec3(1, 0, 0), upper.x[2] = Vec3(0, 1, 0);
  upper.x[3] = Vec3(0.2, 0.3, 1);
  lower.x[0] = Vec3(-0.3, -0.3, 0), lower.x[1] = Vec3(1.5, -0.2, 0),
  lower.x[2] = Vec3(-0.2, 1.6, 0);
  lower.x[3] = Vec3(0.3, 0.3, -1);
  const NodalTetFaces faces_a = all_surface(upper), faces_b = all_surface(lower);
  auto every = [](bool, int, int, int, double) { return true; };
  const auto evaluate = [&](const TetCorners& a, const TetCorners& b) {
    TetGeometry ga, gb;
    compute_tet_geometry(a, ga);
    compute_tet_geometry(b, gb);
    return nodal_contact(ga, faces_a, gb, faces_b, 1e9, every);
  };
  double worst = 0.0;
  int pairs = 0;
  for (int trial = 0; trial < 200; ++trial) {
    TetCorners a = upper, b = lower;
    for (int c = 0; c < 4; ++c) {
      a.x[c] += 0.01 * Vec3(jitter(rng), jitter(rng), jitter(rng));
      b.x[c] += 0.01 * Vec3(jitter(rng), jitter(rng), jitter(rng));
    }
    for (int c = 0; c < 3; ++c) a.x[c].z() -= 0.02;
    const ContactPairResult r = evaluate(a, b);
    if (!r.overlapping) continue;
    ++pairs;
    const double h = 1e-7;
    double error = 0.0;
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) {
        TetCorners plus = a, minus = a;
        plus.x[c][k] += h, minus.x[c][k] -= h;
        const double on_a = -(evaluate(plus, b).energy - evaluate(minus, b).energy) / (2 * h);
        error = std::max(error, std::abs(on_a - r.force_contactor[c][k]));
        plus = b, minus = b;
        plus.x[c][k] += h, minus.x[c][k] -= h;
        const double on_b = -(evaluate(a, plus).energy - evaluate(a, minus).energy) / (2 * h);
        error = std::max(error, std::abs(on_b - r.force_target[c][k]));
      }
    worst = std::max(worst, error / largest_nodal_force(r));
  }
  std::printf("%d pairs in contact; largest force error / largest force: %.3e\n", pairs, worst);
  return worst < 1e-6 ? 0 : 1;
}
