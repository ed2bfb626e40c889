// A scene of one body of rock (E = 30 GPa, ν = 0.25, 2500 kg/m³) for tests that build a model
// from a mesh made in code.
#pragma once

#include <string>

#include "core/scene.hpp"

namespace fdem::test {

inline Scene one_rock_body(const std::string& body_name, double damping = 0.0) {
  Scene scene;
  scene.source_path = "test.yaml";
  MaterialSpec rock;
  rock.name = "rock";
  rock.density = 2500;
  rock.elastic.young = 3e10;
  rock.elastic.poisson = 0.25;
  rock.damping = damping;
  scene.materials.push_back(rock);
  BodySpec body;
  body.name = body_name;
  body.material = 0;
  scene.bodies.push_back(body);
  return scene;
}

}  // namespace fdem::test
