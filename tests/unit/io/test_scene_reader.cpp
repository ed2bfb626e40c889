// Scene reader: every supported key of a full scene lands in the right field, defaults, --set
// overrides, and the content of each error message (file, line, key path, what is valid).
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/scene_reader.hpp"
#include "minimal_scene.hpp"

using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

using namespace fdem::test_scenes;

namespace {

std::string scene_file(const std::string& name) {
  return std::string(FDEM_TEST_DATA) + "/scenes/" + name;
}

}  // namespace

TEST_CASE("nearest_name suggests the closest candidate only when it is close", "[io]") {
  const std::vector<std::string> keys = {"density", "elastic", "damping", "contact", "fracture"};
  CHECK(fdem::nearest_name("densty", keys) == "density");
  CHECK(fdem::nearest_name("Density", keys) == "density");  // case does not count
  CHECK(fdem::nearest_name("elastc", keys) == "elastic");
  CHECK(fdem::nearest_name("contacts", keys) == "contact");
  CHECK(fdem::nearest_name("fractur", keys) == "fracture");
  CHECK(fdem::nearest_name("temperature", keys).empty());
  CHECK(fdem::nearest_name("xyz", keys).empty());
  CHECK(fdem::nearest_name("density", {}).empty());
}

TEST_CASE("a full scene file reads every key into the right field", "[io]") {
  const fdem::Scene s = fdem::read_scene(scene_file("full_scene.yaml"));
  CHECK(s.name == "full-scene");
  CHECK(s.source_path == scene_file("full_scene.yaml"));
  CHECK(s.time.end == 0.25);
  CHECK_FALSE(s.time.auto_step);
  CHECK(s.time.step == 2.0e-6);
  CHECK(s.time.safety == 0.4);
  CHECK(s.gravity == fdem::Vec3(0, 0, -9.81));

  REQUIRE(s.materials.size() == 2);
  const fdem::MaterialSpec& granite = s.materials[0];
  CHECK(granite.name == "granite");
  CHECK(granite.density == 2700);
  CHECK(granite.elastic.model == fdem::ElasticModel::st_venant_kirchhoff);
  CHECK(granite.elastic.young == 30.0e9);
  CHECK(granite.elastic.poisson == 0.25);
  CHECK(granite.damping == 0.05);
  CHECK_FALSE(granite.contact.auto_penalty);
  CHECK(granite.contact.penalty == 3.0e11);
  CHECK(granite.contact.friction == 0.6);
  REQUIRE(granite.fracture.has_value());
  CHECK(granite.fracture->tensile_strength == 5.0e6);
  CHECK(granite.fracture->cohesion == 10.0e6);
  CHECK(granite.fracture->friction_angle_deg == 30);
  CHECK(granite.fracture->energy_I == 50);
  CHECK(granite.fracture->energy_II == 250);
  CHECK(granite.fracture->softening_a == 0.5);
  CHECK(granite.fracture->softening_b == 2.0);
  CHECK(granite.fracture->softening_c == 5.0);

  const fdem::MaterialSpec& mortar = s.materials[1];
  CHECK(mortar.name == "mortar");
  CHECK(mortar.density == 1800);
  CHECK(mortar.elastic.model == fdem::ElasticModel::neo_hookean);  // default model
  CHECK(mortar.elastic.young == 1.0e9);
  CHECK(mortar.elastic.poisson == 0.2);
  CHECK(mortar.damping == 0.0);
  CHECK(mortar.contact.auto_penalty);
  CHECK(mortar.contact.friction == 0.0);
  CHECK_FALSE(mortar.fracture.has_value());

  REQUIRE(s.bodies.size() == 3);
  const fdem::BodySpec& base = s.bodies[0];
  CHECK(base.name == "base");
  CHECK(base.mesh.kind == fdem::MeshSpec::Kind::box);
  CHECK(base.mesh.box.min == fdem::Vec3(-1, -1, -0.2));
  CHECK(base.mesh.box.max == fdem::Vec3(1, 1, 0));
  CHECK(base.mesh.box.cells[0] == 8);
  CHECK(base.mesh.box.cells[1] == 4);
  CHECK(base.mesh.box.cells[2] == 1);
  CHECK(base.material == 0);
  CHECK(base.fixed);
  CHECK(base.joints == fdem::JointPlacement::none);

  const fdem::BodySpec& block = s.bodies[1];
  CHECK(block.name == "block");
  CHECK(block.mesh.kind == fdem::MeshSpec::Kind::file);
  // Relative mesh paths are resolved against the scene file's folder.
  CHECK(block.mesh.file == std::string(FDEM_TEST_DATA) + "/gmsh/cube_two_volumes_ascii.msh");
  CHECK(block.mesh.physical == "left");
  CHECK(block.material == 1);
  CHECK_FALSE(block.fixed);
  CHECK(block.velocity == fdem::Vec3(0, 0, -1));
  CHECK(block.angular_velocity == fdem::Vec3(0, 0.5, 0));

  const fdem::BodySpec& unnamed = s.bodies[2];
  CHECK(unnamed.name == "body2");  // default name body<index>
  CHECK(unnamed.joints == fdem::JointPlacement::all);
  CHECK(unnamed.mesh.box.cells[0] == 1);  // default one cell per direction
  CHECK(unnamed.mesh.box.cells[2] == 1);
  CHECK(unnamed.velocity == fdem::Vec3::Zero());

  REQUIRE(s.interfaces.size() == 1);
  CHECK(s.interfaces[0].body_a == 1);
  CHECK(s.interfaces[0].body_b == 0);
  CHECK(s.interfaces[0].fracture.tensile_strength == 0.2e6);
  CHECK(s.interfaces[0].fracture.cohesion == 0.4e6);
  CHECK(s.interfaces[0].fracture.friction_angle_deg == 35);
  CHECK(s.interfaces[0].fracture.energy_I == 10);
  CHECK(s.interfaces[0].fracture.energy_II == 50);
  CHECK(s.interfaces[0].fracture.softening_a == 0.63);  // defaults
  CHECK(s.interfaces[0].fracture.softening_b == 1.8);
  CHECK(s.interfaces[0].fracture.softening_c == 6.0);

  REQUIRE(s.loads.size() == 2);
  CHECK(s.loads[0].bodies == std::vector<int>{0, 2});
  CHECK_FALSE(s.loads[0].region.has_value());
  CHECK(s.loads[0].velocity == fdem::Vec3(0.01, 0, 0));
  CHECK(s.loads[0].dof_mask == 7u);
  CHECK(s.loads[1].bodies.empty());
  REQUIRE(s.loads[1].region.has_value());
  CHECK(s.loads[1].region->min == fdem::Vec3(-1, -1, -0.2));
  CHECK(s.loads[1].region->max == fdem::Vec3(-0.9, 1, 0));
  // "~" and "null" leave x and z free: only y (bit 1) is prescribed.
  CHECK(s.loads[1].dof_mask == 2u);
  CHECK(s.loads[1].velocity == fdem::Vec3(0, -0.02, 0));

  CHECK(s.output.every == 0.01);
  CHECK(s.output.checkpoint_every == 0.1);
  CHECK(s.output.energy_every == 0.001);
  CHECK(s.output.fields ==
        std::vector<std::string>{"displacement", "velocity", "stress", "damage", "contact_force"});
  CHECK(s.contact_buffer == 0.002);
}

TEST_CASE("omitted optional keys take the documented defaults", "[io]") {
  const fdem::Scene s = fdem::parse_scene(join_lines(minimal_lines()), "dir/my-scene.yaml");
  CHECK(s.name == "my-scene");  // file stem
  CHECK(s.time.end == 0.1);
  CHECK(s.time.auto_step);
  CHECK(s.time.safety == 0.7);
  CHECK(s.gravity == fdem::Vec3::Zero());
  REQUIRE(s.materials.size() == 1);
  CHECK(s.materials[0].contact.auto_penalty);
  CHECK(s.materials[0].elastic.model == fdem::ElasticModel::neo_hookean);
  REQUIRE(s.bodies.size() == 1);
  CHECK_FALSE(s.bodies[0].fixed);
  CHECK(s.interfaces.empty());
  CHECK(s.loads.empty());
  CHECK(s.output.every == 0.0);
  CHECK(s.output.fields == std::vector<std::string>{"displacement", "velocity", "stress"});
  CHECK(s.contact_buffer < 0.0);  // automatic
  CHECK(s.contact_exact_narrowing);
  CHECK(s.contact_friction_anchor_lag == 0.05);
  CHECK(s.contact_body_dashpot);  // contact.dashpot: bodies
  CHECK(s.parallel.rebalance_threshold == 1.10);
  CHECK(s.parallel.redistribute_every == 0);

  SECTION("'auto' spelled out is the same as omitted") {
    const fdem::Scene a = fdem::parse_scene(
        minimal_with(1, "time: {end: 0.1, step: auto}") + "contact: {buffer: auto}\n",
        "scene.yaml");
    CHECK(a.time.auto_step);
    CHECK(a.contact_buffer < 0.0);
    const fdem::Scene b =
        fdem::parse_scene(minimal_with(5,
                                       "    elastic: {young: 1.0e9, poisson: 0.25}\n"
                                       "    contact: {penalty: auto, friction: 0.3}"),
                          "scene.yaml");
    CHECK(b.materials[0].contact.auto_penalty);
    CHECK(b.materials[0].contact.friction == 0.3);
  }
}

TEST_CASE("unknown keys are reported with file, line, path and the nearest valid key", "[io]") {
  SECTION("misspelt material key") {
    const std::string msg = input_error(minimal_with(4, "    densty: 2500"));
    CHECK_THAT(msg, StartsWith("scene.yaml:4:5: materials.rock.densty: unknown key 'densty'."));
    CHECK_THAT(msg, Contains("Did you mean 'density'?"));
    CHECK_THAT(msg, Contains("Valid keys here: density, elastic, damping, contact, fracture."));
  }
  SECTION("misspelt top-level key") {
    const std::string msg = input_error(minimal_plus("gravty: [0, 0, -9.81]\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:10:1: gravty: unknown key 'gravty'."));
    CHECK_THAT(msg, Contains("Did you mean 'gravity'?"));
  }
  SECTION("misspelt key inside a flow mapping of a body") {
    const std::string msg = input_error(
        minimal_with(8, "    mesh: {box: {min: [0, 0, 0], max: [1, 1, 1], cels: [2, 2, 2]}}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:8:"));
    CHECK_THAT(msg, Contains("bodies[0].mesh.box.cels: unknown key 'cels'. Did you mean 'cells'?"));
  }
  SECTION("a key far from every valid one gets no suggestion but the list") {
    const std::string msg = input_error(minimal_with(1, "time: {end: 0.1, temperature: 300}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:1:18: time.temperature: unknown key 'temperature'."));
    CHECK_THAT(msg, !Contains("Did you mean"));
    CHECK_THAT(msg, Contains("Valid keys here: end, step, safety."));
  }
}

TEST_CASE("wrong value types name the key and what was expected", "[io]") {
  SECTION("text where a number goes") {
    const std::string msg = input_error(minimal_with(4, "    density: heavy"));
    CHECK(msg == "scene.yaml:4:14: materials.rock.density: expected a number, got 'heavy'");
  }
  SECTION("a list where a number goes") {
    const std::string msg = input_error(minimal_with(1, "time: {end: [0.1]}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:1:13: time.end: expected a number"));
  }
  SECTION("two numbers where a vector of three goes") {
    const std::string msg = input_error(minimal_plus("gravity: [0, -9.81]\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:10:10: gravity: expected three numbers [x, y, z]"));
  }
  SECTION("a non-integer cell count") {
    const std::string msg = input_error(
        minimal_with(8, "    mesh: {box: {min: [0, 0, 0], max: [1, 1, 1], cells: [2, 2.5, 2]}}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:8:"));
    CHECK_THAT(msg, Contains("bodies[0].mesh.box.cells: expected an integer, got '2.5'"));
  }
  SECTION("a word where true/false goes") {
    const std::string msg = input_error(minimal_plus("    fixed: sometimes\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:10:12: bodies[0].fixed: expected true or false, got "
                               "'sometimes'"));
  }
  SECTION("a velocity of a fixed body (it would be dropped)") {
    const std::string msg =
        input_error(minimal_plus("    fixed: true\n    angular_velocity: [0, 0, 1]\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:11:23: bodies[0].angular_velocity: a fixed body does "
                               "not move"));
    CHECK_THAT(input_error(minimal_plus("    fixed: true\n    velocity: [1, 0, 0]\n")),
               StartsWith("scene.yaml:11:15: bodies[0].velocity: a fixed body does not move"));
  }
}

TEST_CASE("missing required keys name the parent's line and the missing key", "[io]") {
  SECTION("time.end") {
    const std::string msg = input_error(minimal_with(1, "time: {safety: 0.5}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:1:7: time.end: missing required key 'end'"));
  }
  SECTION("density") {
    auto lines = minimal_lines();
    lines.erase(lines.begin() + 3);  // line 4 (density); elastic moves up to line 4
    const std::string msg = input_error(join_lines(lines));
    CHECK_THAT(
        msg, StartsWith("scene.yaml:4:5: materials.rock.density: missing required key 'density'"));
  }
  SECTION("elastic.young") {
    const std::string msg = input_error(minimal_with(5, "    elastic: {poisson: 0.25}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:5:14: materials.rock.elastic.young: missing required "
                               "key 'young'"));
  }
  SECTION("bodies") {
    auto lines = minimal_lines();
    lines.resize(5);
    const std::string msg = input_error(join_lines(lines));
    CHECK_THAT(msg, StartsWith("scene.yaml:1:1: bodies: missing required key 'bodies'"));
  }
  SECTION("an empty bodies list") {
    auto lines = minimal_lines();
    lines.resize(5);
    const std::string msg = input_error(join_lines(lines) + "bodies: []\n");
    CHECK_THAT(msg, StartsWith("scene.yaml:6:9: bodies: expected a list of bodies"));
  }
  SECTION("an empty file") {
    const std::string msg = input_error("");
    CHECK_THAT(msg, StartsWith("scene.yaml"));
    CHECK_THAT(msg, Contains("expected a mapping (key: value pairs)"));
  }
}

TEST_CASE("impossible values are rejected with the valid range", "[io]") {
  SECTION("negative density") {
    const std::string msg = input_error(minimal_with(4, "    density: -2500"));
    CHECK(msg ==
          "scene.yaml:4:14: materials.rock.density: -2500 is impossible: density (kg/m^3) "
          "must be > 0");
  }
  SECTION("Poisson's ratio 0.5") {
    const std::string msg =
        input_error(minimal_with(5, "    elastic: {young: 1.0e9, poisson: 0.5}"));
    CHECK(msg ==
          "scene.yaml:5:38: materials.rock.elastic.poisson: 0.5 is impossible: Poisson's "
          "ratio must satisfy -1 < poisson < 0.5");
  }
  SECTION("Poisson's ratio -1") {
    const std::string msg =
        input_error(minimal_with(5, "    elastic: {young: 1.0e9, poisson: -1}"));
    CHECK_THAT(msg,
               StartsWith("scene.yaml:5:38: materials.rock.elastic.poisson: -1 is impossible"));
    CHECK_THAT(msg, Contains("-1 < poisson < 0.5"));
  }
  SECTION("Young's modulus zero") {
    const std::string msg = input_error(minimal_with(5, "    elastic: {young: 0, poisson: 0.2}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:5:22: materials.rock.elastic.young: 0 is impossible"));
  }
  SECTION("safety above one") {
    const std::string msg = input_error(minimal_with(1, "time: {end: 0.1, safety: 1.5}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:1:26: time.safety: must be in (0, 1]"));
  }
  SECTION("negative end time") {
    const std::string msg = input_error(minimal_with(1, "time: {end: -1}"));
    CHECK_THAT(msg,
               StartsWith("scene.yaml:1:13: time.end: -1 is impossible: end time (s) must be > 0"));
  }
  SECTION("box max not above min") {
    const std::string msg =
        input_error(minimal_with(8, "    mesh: {box: {min: [0, 0, 0], max: [1, 0, 1]}}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:8:39: bodies[0].mesh.box.max: each component of max "
                               "must be larger than min's"));
  }
  SECTION("zero cells") {
    const std::string msg = input_error(
        minimal_with(8, "    mesh: {box: {min: [0, 0, 0], max: [1, 1, 1], cells: [2, 0, 2]}}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:8:61: bodies[0].mesh.box.cells: each cell count must be "
                               ">= 1"));
  }
  SECTION("damping ratio of one") {
    const std::string msg = input_error(minimal_with(4, "    density: 2500\n    damping: 1.0"));
    CHECK_THAT(msg, StartsWith("scene.yaml:5:14: materials.rock.damping: 1 is too large"));
  }
  SECTION("friction angle of 90 degrees") {
    const std::string msg = input_error(minimal_with(
        4,
        "    density: 2500\n    fracture: {tensile_strength: 1e6, cohesion: 2e6, friction_angle: "
        "90, energy_I: 10, energy_II: 50}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:5:"));
    CHECK_THAT(msg, Contains("materials.rock.fracture.friction_angle: 90 is impossible"));
    CHECK_THAT(msg, Contains("0 <= angle < 90"));
  }
  SECTION("friction anchors that never follow the contact") {
    const std::string msg =
        input_error(minimal_with(1, "time: {end: 0.1}") + "contact: {friction_anchor_lag: 0}\n");
    CHECK_THAT(msg, Contains("contact.friction_anchor_lag: 0 is impossible"));
    CHECK_THAT(msg, Contains("must be > 0"));
    const fdem::Scene s = fdem::parse_scene(
        minimal_with(1, "time: {end: 0.1}") + "contact: {friction_anchor_lag: 0.2}\n",
        "scene.yaml");
    CHECK(s.contact_friction_anchor_lag == 0.2);
  }
}

TEST_CASE("references between sections are checked", "[io]") {
  SECTION("unknown material, with a suggestion") {
    const std::string msg = input_error(minimal_with(9, "    material: rok"));
    CHECK(msg ==
          "scene.yaml:9:15: bodies[0].material: no material named 'rok'. Did you mean "
          "'rock'? Materials: rock.");
  }
  SECTION("duplicate body names") {
    const std::string msg =
        input_error(minimal_plus("  - name: block\n    mesh: {box: {min: [2, 0, 0], max: [3, 1, "
                                 "1]}}\n    material: rock\n"));
    CHECK_THAT(msg,
               StartsWith("scene.yaml:10:11: bodies[1].name: body name 'block' is used twice"));
  }
  SECTION("unknown elastic model, with a suggestion") {
    const std::string msg = input_error(
        minimal_with(5, "    elastic: {model: neo-hooke, young: 1.0e9, poisson: 0.25}"));
    CHECK(msg ==
          "scene.yaml:5:22: materials.rock.elastic.model: 'neo-hooke' is not valid. Did you "
          "mean 'neo-hookean'? Valid values: neo-hookean, st-venant-kirchhoff.");
  }
  SECTION("joints: all without a fracture block") {
    const std::string msg = input_error(minimal_plus("    joints: all\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:10:13: bodies[0].joints: 'all' needs fracture "
                               "properties: add a 'fracture:' block to material 'rock'"));
  }
  SECTION("joints value misspelt") {
    const std::string msg = input_error(minimal_plus("    joints: al\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:10:13: bodies[0].joints: 'al' is not valid. Did you "
                               "mean 'all'? Valid values: none, all, interfaces."));
  }
  SECTION("interface naming an unknown body") {
    const std::string msg = input_error(minimal_plus(
        "interfaces:\n"
        "  - between: [block, blok2]\n"
        "    fracture: {tensile_strength: 1e6, cohesion: 2e6, friction_angle: 30, energy_I: 10, "
        "energy_II: 50}\n"));
    CHECK(msg ==
          "scene.yaml:11:22: interfaces[0].between: no body named 'blok2'. Did you mean "
          "'block'? Bodies: block.");
  }
  SECTION("interface with three bodies") {
    const std::string msg = input_error(minimal_plus(
        "interfaces:\n"
        "  - between: [block, block, block]\n"
        "    fracture: {tensile_strength: 1e6, cohesion: 2e6, friction_angle: 30, energy_I: 10, "
        "energy_II: 50}\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:11:14: interfaces[0].between: expected exactly two body "
                               "names"));
  }
  SECTION("load naming an unknown body") {
    const std::string msg =
        input_error(minimal_plus("loads:\n  - {bodies: [blocks], velocity: [0, 0, 0]}\n"));
    CHECK(msg ==
          "scene.yaml:11:15: loads[0].bodies: no body named 'blocks'. Did you mean "
          "'block'? Bodies: block.");
  }
  SECTION("mesh file that does not exist") {
    const std::string msg =
        input_error(minimal_with(8, "    mesh: {file: meshes/missing.msh, physical: stones}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:8:18: bodies[0].mesh.file: mesh file "
                               "'meshes/missing.msh' does not exist (paths are relative to the "
                               "scene file)"));
  }
  SECTION("mesh with both box and file") {
    const std::string msg = input_error(
        minimal_with(8, "    mesh: {box: {min: [0, 0, 0], max: [1, 1, 1]}, file: a.msh}"));
    CHECK_THAT(msg, StartsWith("scene.yaml:8:11: bodies[0].mesh: give either 'box' or 'file'"));
  }
}

TEST_CASE("load velocities with null components prescribe only the given ones", "[io]") {
  const fdem::Scene s = fdem::parse_scene(
      minimal_plus("loads:\n"
                   "  - {bodies: [block], velocity: [null, 0.5, ~]}\n"
                   "  - {region: {box: {min: [0, 0, 0], max: [1, 1, 0.1]}}, velocity: [1, 2, 3]}\n"
                   "  - {bodies: [block], velocity: [null, null, null]}\n"),
      "scene.yaml");
  REQUIRE(s.loads.size() == 3);
  CHECK(s.loads[0].dof_mask == 0b010u);
  CHECK(s.loads[0].velocity == fdem::Vec3(0, 0.5, 0));
  CHECK(s.loads[0].bodies == std::vector<int>{0});
  CHECK(s.loads[1].dof_mask == 0b111u);
  CHECK(s.loads[1].velocity == fdem::Vec3(1, 2, 3));
  CHECK(s.loads[2].dof_mask == 0u);

  SECTION("a load without a target") {
    const std::string msg = input_error(minimal_plus("loads:\n  - {velocity: [0, 0, 0]}\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:11:5: loads[0]: a load needs 'bodies' or 'region'"));
  }
  SECTION("an inverted region box") {
    const std::string msg = input_error(minimal_plus(
        "loads:\n  - {region: {box: {min: [0, 0, 1], max: [1, 1, 0]}}, velocity: [0, 0, 0]}\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:11:42: loads[0].region.box.max: each component of max "
                               "must be at least min's"));
  }
  SECTION("a velocity with two components") {
    const std::string msg =
        input_error(minimal_plus("loads:\n  - {bodies: [block], velocity: [0, 0]}\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:11:33: loads[0].velocity: expected [vx, vy, vz] in m/s "
                               "(null leaves a component free)"));
  }
}

TEST_CASE("malformed YAML is reported with its line", "[io]") {
  SECTION("an unclosed flow mapping") {
    const std::string msg =
        input_error(minimal_with(5, "    elastic: {young: 1.0e9, poisson: 0.25"));
    CHECK_THAT(msg, StartsWith("scene.yaml:6:"));
    CHECK_THAT(msg, Contains("not valid YAML"));
  }
  SECTION("a tab-indented / mis-indented key") {
    const std::string msg = input_error(minimal_with(4, "     density: 2500"));
    CHECK_THAT(msg, StartsWith("scene.yaml:5:"));
    CHECK_THAT(msg, Contains("not valid YAML"));
  }
}

TEST_CASE("overrides from --set replace values before validation", "[io]") {
  const std::string text = join_lines(minimal_lines());
  SECTION("a scalar") {
    const fdem::Scene s = fdem::parse_scene(text, "scene.yaml", {"time.end=0.5"});
    CHECK(s.time.end == 0.5);
  }
  SECTION("a material property by name") {
    const fdem::Scene s = fdem::parse_scene(text, "scene.yaml", {"materials.rock.density=3000"});
    CHECK(s.materials[0].density == 3000);
  }
  SECTION("a list item by index, with a YAML list value") {
    const fdem::Scene s = fdem::parse_scene(text, "scene.yaml", {"bodies.0.velocity=[1,0,0]"});
    CHECK(s.bodies[0].velocity == fdem::Vec3(1, 0, 0));
  }
  SECTION("a key that was not in the file, and several overrides in order") {
    const fdem::Scene s = fdem::parse_scene(
        text, "scene.yaml", {"time.safety=0.3", "gravity=[0, 0, -10]", "time.safety=0.2"});
    CHECK(s.time.safety == 0.2);
    CHECK(s.gravity == fdem::Vec3(0, 0, -10));
  }
  SECTION("an override is validated like the file") {
    const std::string msg = input_error(text, {"materials.rock.density=-1"});
    CHECK_THAT(msg, Contains("materials.rock.density: -1 is impossible"));
    const std::string typo = input_error(text, {"time.ned=1"});
    CHECK_THAT(typo, Contains("time.ned: unknown key 'ned'. Did you mean 'end'?"));
  }
  SECTION("bad override syntax") {
    CHECK_THAT(input_error(text, {"time.end"}),
               StartsWith("--set time.end: expected key.path=value (e.g. --set time.end=0.2)"));
    CHECK_THAT(input_error(text, {"=0.5"}), Contains("expected key.path=value"));
    CHECK_THAT(input_error(text, {"bodies.3.velocity=[1,0,0]"}),
               Contains("index 3 is past the end of the list"));
    CHECK_THAT(input_error(text, {"time.0=1"}), Contains("'0' indexes a list, but scene.yaml has "
                                                         "no list there"));
    CHECK_THAT(input_error(text, {"gravity=[0, 0"}), Contains("the value is not valid YAML"));
  }
}

TEST_CASE("read_scene reads from disk and reports a missing file", "[io]") {
  const std::string missing = scene_file("no_such_scene.yaml");
  try {
    fdem::read_scene(missing);
    FAIL("expected an InputError");
  } catch (const fdem::InputError& e) {
    CHECK_THAT(e.what(), StartsWith(missing + ": cannot open the scene file"));
  }
  // Overrides pass through read_scene too.
  const fdem::Scene s = fdem::read_scene(scene_file("full_scene.yaml"), {"time.end=1.5"});
  CHECK(s.time.end == 1.5);
}

TEST_CASE("ambiguous or oddly shaped input is an input error with a location", "[io]") {
  SECTION("a key given twice in one mapping") {
    // YAML forbids it and yaml-cpp would silently keep the first value.
    const std::string msg = input_error(minimal_with(4, "    density: 2500\n    density: 3000"));
    CHECK_THAT(msg, StartsWith("scene.yaml:5:5: materials.rock.density: key 'density' is given "
                               "twice"));
  }
  SECTION("a top-level section given twice") {
    const std::string msg = input_error(
        minimal_plus("materials:\n  rock: {density: 1, elastic: {young: 1, poisson: 0}}\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:10:1: materials: key 'materials' is given twice"));
  }
  SECTION("a material defined twice") {
    const std::string msg = input_error(minimal_with(
        5,
        "    elastic: {young: 1.0e9, poisson: 0.25}\n  rock: {density: 1, elastic: {young: 1, "
        "poisson: 0}}"));
    CHECK(msg == "scene.yaml:6:3: materials.rock: material 'rock' is defined twice");
  }
  SECTION("a list used as a key") {
    const std::string msg = input_error(minimal_plus("[a, b]: 1\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:10:1: (top level): a key must be a plain name"));
  }
  SECTION("a default body name that repeats an explicit one") {
    // Body 1 has no name, so it is called body1, which body 0 already uses.
    const std::string msg =
        input_error(minimal_with(7, "  - name: body1") +
                    "  - mesh: {box: {min: [2, 0, 0], max: [3, 1, 1]}}\n    material: rock\n");
    CHECK_THAT(msg, StartsWith("scene.yaml:10:5: bodies[1].name: body name 'body1' is used twice"));
  }
  SECTION("an interface between a body and itself") {
    const std::string msg = input_error(minimal_plus(
        "interfaces:\n"
        "  - between: [block, block]\n"
        "    fracture: {tensile_strength: 1e6, cohesion: 2e6, friction_angle: 30, energy_I: 10, "
        "energy_II: 50}\n"));
    CHECK_THAT(msg, StartsWith("scene.yaml:11:14: interfaces[0].between: an interface joins two "
                               "different bodies"));
  }
}

TEST_CASE("errors in --set values point at the override, not at a line of the file", "[io]") {
  const std::string text = join_lines(minimal_lines());
  SECTION("an impossible value") {
    const std::string msg = input_error(text, {"materials.rock.density=-1"});
    CHECK(msg ==
          "scene.yaml: --set materials.rock.density=-1: materials.rock.density: -1 is "
          "impossible: density (kg/m^3) must be > 0");
  }
  SECTION("inside a list item set by index") {
    const std::string msg = input_error(text, {"bodies.0.velocity=[1, x, 0]"});
    CHECK(msg ==
          "scene.yaml: --set bodies.0.velocity=[1, x, 0]: bodies[0].velocity[1]: expected "
          "a number, got 'x'");
  }
  SECTION("an unknown key that only the override created") {
    const std::string msg = input_error(text, {"outptu.every=0.1"});
    CHECK_THAT(msg, StartsWith("scene.yaml: --set outptu.every=0.1: outptu: unknown key 'outptu'. "
                               "Did you mean 'output'?"));
  }
  SECTION("a mapping replaced by an override") {
    const std::string msg = input_error(text, {"materials.rock.elastic={young: 1e9}"});
    CHECK(msg ==
          "scene.yaml: --set materials.rock.elastic={young: 1e9}: "
          "materials.rock.elastic.poisson: missing required key 'poisson'");
  }
  SECTION("a value in the file next to an override keeps its line") {
    const std::string msg =
        input_error(minimal_with(4, "    density: -5"), {"materials.rock.elastic.young=2e9"});
    CHECK_THAT(msg, StartsWith("scene.yaml:4:14: materials.rock.density: -5 is impossible"));
  }
  SECTION("a path that goes through a plain value") {
    const std::string msg = input_error(text, {"time.end.value=1"});
    CHECK_THAT(msg, StartsWith("--set time.end.value=1: 'end' is not a mapping, so it has no "
                               "key 'value'"));
    CHECK_THAT(input_error(text, {"bodies.name=x"}),
               StartsWith("--set bodies.name=x: 'bodies' is not a mapping"));
    CHECK_THAT(input_error(text, {"bodies.99999999999999999999.name=x"}),
               Contains("is past the end of the list"));
  }
}
