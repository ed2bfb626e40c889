// The `fdem` command: run | check | --version (see docs/scene-format.md and README.md).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "contact/contact_stage.hpp"
#include "core/error.hpp"
#include "drivers/histories.hpp"
#include "drivers/interrupt.hpp"
#include "drivers/process_memory.hpp"
#include "drivers/run_limits.hpp"
#include "drivers/simulation.hpp"
#include "fracture/joint_stage.hpp"
#include "io/scene_reader.hpp"
#include "parallel/communicator.hpp"
#include "parallel/model_file.hpp"

namespace {

// Exit codes (README.md): 1 is left to bugs (an internal error, an uncaught exception).
constexpr int exit_bad_input = 2;          // the scene, mesh, command line or checkpoint is wrong
constexpr int exit_numerical_failure = 3;  // the run became unstable
constexpr int exit_io_failure = 4;         // an output or checkpoint file could not be written
constexpr int exit_interrupted = 5;        // SIGTERM/SIGINT/SIGUSR1: checkpoint + summary written

const char* usage =
    "usage:\n"
    "  fdem run SCENE.yaml [-o OUTDIR] [--set key.path=value ...] [--restart CHECKPOINT.h5] [-q]\n"
    "  mpirun -np N fdem run SCENE.yaml ...   (N ranks; results identical to one rank)\n"
    "  fdem check SCENE.yaml [--set key.path=value ...]\n"
    "  fdem prepare MESH.msh [-o MODEL.h5] [--block-rows N]   (a Gmsh mesh into a model file)\n"
    "  fdem --version\n";

// Materials of free bodies with friction and no element damping: sliding, an elastic body
// vibrates on its contact and its mean friction falls below μN (docs/verification.md, "Sliding
// too fast").
std::vector<std::string> sliding_advice(const fdem::Scene& scene) {
  std::vector<bool> free_material(scene.materials.size(), false);
  for (const auto& b : scene.bodies)
    if (!b.fixed) free_material[static_cast<std::size_t>(b.material)] = true;
  std::vector<std::string> lines;
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    const fdem::MaterialSpec& material = scene.materials[m];
    if (!free_material[m] || !(material.contact.friction > 0.0) || material.damping > 0.0) continue;
    lines.push_back("material '" + material.name +
                    "' has friction and no element damping: a body of it that slides vibrates "
                    "on its contacts and slides too far (3-9x a rigid block's slip at 1.02 mu); "
                    "damping: 0.5 brings that within 4 % (docs/verification.md, \"Sliding too "
                    "fast\")");
  }
  return lines;
}

// Materials whose bodies may touch (one of them free) and of which only one has friction: their
// contact takes the smaller coefficient, so it has none (a block with friction on a base without
// slides freely).
std::vector<std::string> friction_mix_advice(const fdem::Scene& scene) {
  const std::size_t n = scene.materials.size();
  std::vector<bool> used(n, false), free(n, false);
  for (const auto& b : scene.bodies) {
    used[static_cast<std::size_t>(b.material)] = true;
    if (!b.fixed) free[static_cast<std::size_t>(b.material)] = true;
  }
  std::vector<std::string> lines;
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) {
      const double mu_a = scene.materials[a].contact.friction;
      const double mu_b = scene.materials[b].contact.friction;
      if (!used[a] || !used[b] || !(free[a] || free[b]) || !(mu_a > 0.0) || mu_b > 0.0) continue;
      char line[512];
      std::snprintf(line, sizeof line,
                    "contact between materials '%s' (friction %g) and '%s' (none) is frictionless: "
                    "a pair takes the smaller coefficient; give '%s' a friction too",
                    scene.materials[a].name.c_str(), mu_a, scene.materials[b].name.c_str(),
                    scene.materials[b].name.c_str());
      lines.emplace_back(line);
    }
  return lines;
}

int check(const fdem::Scene& scene) {
  auto sim = fdem::make_simulation(scene, {});
  const fdem::Model& model = sim->model();
  std::printf("scene '%s' (%s)\n", scene.name.c_str(), scene.source_path.c_str());
  std::printf("  materials: %zu\n", scene.materials.size());
  for (const auto& m : scene.materials)
    std::printf(
        "    %-16s density %g kg/m^3, E %g Pa, nu %g, %s%s\n", m.name.c_str(), m.density,
        m.elastic.young, m.elastic.poisson,
        m.elastic.model == fdem::ElasticModel::neo_hookean ? "neo-hookean" : "st-venant-kirchhoff",
        m.damping > 0 ? (", damping ratio " + std::to_string(m.damping)).c_str() : "");
  std::printf("  bodies: %zu\n", scene.bodies.size());
  for (std::size_t b = 0; b < scene.bodies.size(); ++b)
    std::printf("    %-16s %d discrete element(s), material %s%s\n", scene.bodies[b].name.c_str(),
                model.pieces.pieces_in_body(static_cast<std::int32_t>(b)),
                scene.materials[scene.bodies[b].material].name.c_str(),
                scene.bodies[b].fixed ? ", fixed" : "");
  std::printf("  mesh: %d nodes, %d tetrahedra, %zu discrete elements\n", model.nodes.size(),
              model.tets.size(), model.pieces.size());
  std::printf(
      "  time: end %g s, step %g s (%s; critical %g s), %ld steps (limit %g)\n", scene.time.end,
      sim->time_step(), scene.time.auto_step ? "auto" : "fixed", sim->critical_time_step(),
      fdem::checked_step_count(0.0, scene.time.end, sim->time_step()), scene.limits.max_steps);
  if (sim->time_step() > sim->critical_time_step())  // the run would stop at its blow-up
    std::printf(
        "  advice: time.step is %.3g x the critical step %g s: above the stability limit, the run "
        "will become unstable; use time.step: auto or a step below %g s\n",
        sim->time_step() / sim->critical_time_step(), sim->critical_time_step(),
        sim->critical_time_step());
  std::string ceiling_source;
  const double ceiling = fdem::memory_ceiling_per_rank(scene.limits, 1, &ceiling_source);
  std::printf(
      "  memory: about %s per rank on 1 rank (limit %s, %s)\n",
      fdem::format_bytes(fdem::estimated_bytes_per_rank(fdem::model_size(sim->model()), 1)).c_str(),
      fdem::format_bytes(ceiling).c_str(), ceiling_source.c_str());
  if (const fdem::ContactStage* contact = sim->contact_stage()) {
    std::printf("  contact: buffer %g m, penalties", contact->buffer());
    for (std::size_t m = 0; m < model.materials.size(); ++m)
      std::printf(" %s %g Pa%s", model.materials[m].name.c_str(), contact->material_penalty()[m],
                  m + 1 < model.materials.size() ? "," : "");
    const bool corners = fdem::uses_corner_contact(scene);
    std::printf("; formulation %s%s\n", corners ? "corners" : "potential",
                scene.contact_formulation != fdem::ContactFormulation::automatic ? ""
                : corners ? " (auto: quasi-static throughout, no joints)"
                          : " (auto: potential unless quasi-static throughout without joints)");
    for (const std::string& line : friction_mix_advice(scene))
      std::printf("  advice: %s\n", line.c_str());
    // A penalty far below E: contacts much softer than the bodies (a block on a base at 1e-4 E
    // falls through it).
    for (std::size_t m = 0; m < model.materials.size(); ++m) {
      const double penalty = contact->material_penalty()[m], young = model.materials[m].young;
      if (penalty < 0.01 * young)
        std::printf(
            "  advice: material '%s' has a contact penalty of %.2g x its E (%g Pa against %g Pa): "
            "its contacts are far softer than its bodies, which sink into each other under load, "
            "or through each other where the contact cannot hold the load; the default (auto) is "
            "10 E\n",
            model.materials[m].name.c_str(), penalty / young, penalty, young);
    }
  }
  // Local damping for the whole run damps every vibration, the friction-induced one too.
  if (sim->contact_stage() && !scene.quasi_static.active_until(scene.time.end)) {
    for (const std::string& line : sliding_advice(scene))
      std::printf("  advice: %s\n", line.c_str());
    if (fdem::uses_corner_contact(scene))
      std::printf(
          "  advice: contact.formulation: corners is made for quasi-static holds and for blocks "
          "that stay face to face; in a dynamic run where blocks tumble across each other, a "
          "corner caught beside another block's edge can put energy in (the default example "
          "stops at t = 0.057 s): use potential there (docs/verification.md, \"Corner "
          "contact\")\n");
  }
  if (model.joints.size() > 0)
    std::printf("  joints: %d cohesive joints, %zu laws\n", model.joints.size(),
                sim->joint_stage() ? sim->joint_stage()->laws().size() : std::size_t{0});
  if (sim->initial_equilibrium_residual() >= 0.0)
    std::printf(
        "  initial stress: equilibrium residual at t = 0: %.3g (|net force| / |forces of "
        "the initial stress| over the free components)\n",
        sim->initial_equilibrium_residual());
  if (const fdem::HistoriesSpec& h = scene.output.histories; h.enabled) {
    // Monitors were placed in their tets when the simulation was made (or refused there).
    std::string what;
    for (const int l : h.loads) what += " load " + scene.loads[l].name + ",";
    for (const int b : h.bodies) what += " body " + scene.bodies[b].name + ",";
    for (const auto& m : h.monitors) {
      char stop[80] = "";
      if (m.stop_displacement > 0.0)
        std::snprintf(stop, sizeof stop, " (ends the run when it has moved %g m)",
                      m.stop_displacement);
      what += " monitor " + m.name + stop + ",";
    }
    what.pop_back();
    std::printf("  histories.csv:%s\n", what.c_str());
    for (const std::string& at_rest : fdem::monitors_held_at_rest(scene, model))
      std::printf(
          "  warning: %s, which no velocity or base-motion load moves: its stop_displacement "
          "can never end the run; place the monitor in a body that moves\n",
          at_rest.c_str());
  }
  if (const fdem::QuasiStaticSpec& q = scene.quasi_static; q.enabled()) {
    char local[48] = "";
    if (q.local_damping > 0.0)
      std::snprintf(local, sizeof local, "%slocal damping %g", q.kinetic() ? " and " : "",
                    q.local_damping);
    std::printf("  quasi-static: %s%s", q.kinetic() ? "kinetic damping" : "", local);
    if (q.until < scene.time.end)
      std::printf(" until %g s", q.until);
    else
      std::printf(" for the whole run");
    const fdem::LoadsSettle& settle = sim->loads_settle();
    const std::string loads = fdem::describe_loads_settle(scene, settle);
    // The damping acts on absolute velocities: it holds back the free bodies the ground carries.
    const fdem::LoadsSettle& ground = sim->base_motion_start();
    const bool ground_damped = ground.load >= 0 && ground.time < std::min(q.until, scene.time.end);
    if (!(q.equilibrium_ratio > 0.0))
      std::printf("\n");
    else if (settle.time <= 0.0)
      std::printf("; equilibrium_ratio %g ends the run at equilibrium\n", q.equilibrium_ratio);
    else if (settle.time < std::min(scene.time.end, q.until))
      std::printf("; equilibrium_ratio %g ends the run at equilibrium from t = %g s on (%s)\n",
                  q.equilibrium_ratio, settle.time, loads.c_str());
    else
      std::printf(
          "\n  note: quasi_static.equilibrium_ratio cannot end this run: %s, and the run ends "
          "at equilibrium only once every load is constant%s (a monitor's stop_displacement "
          "can end it)\n",
          loads.c_str(), q.until < scene.time.end ? ", while the damping acts" : "");
    if (ground_damped)
      std::printf(
          "  warning: the ground moves from t = %g s (%s, a base motion) while the quasi-static "
          "damping acts: it holds back the bodies the ground carries; end the damping before "
          "the record starts (quasi_static.until <= %g)\n",
          ground.time, fdem::load_label(scene, ground.load).c_str(), ground.time);
  }
  std::printf("  stages:\n");
  for (const auto& s : sim->plan().describe()) std::printf("    %s\n", s.c_str());
  // The first step, as `fdem run` takes it: bodies placed into each other warn (their contact
  // energy at t = 0, Simulation::check_step), and a scene whose first step fails fails here.
  if (sim->contact_stage()) {
    std::fflush(stdout);
    sim->step();
  }
  return 0;
}

}  // namespace

int run_command(int argc, char** argv, const fdem::Communicator& world);
int prepare_command(const std::vector<std::string>& args, const fdem::Communicator& world);

int main(int argc, char** argv) {
  fdem::give_large_blocks_back_when_freed();
  // Under mpirun every rank runs the same command; one rank alone is a serial run.
  fdem::MpiEnvironment environment(&argc, &argv);
  const fdem::Communicator world = fdem::Communicator::world();
  fdem::install_interrupt_handlers();  // after MPI_Init, so that these handlers are the ones kept
  return run_command(argc, argv, world);
}

// Reports an error: a collective one (every rank has it) once from rank 0 and returns the exit
// code; one that only this rank has ends every rank (the others may wait in a collective).
int fail(const fdem::Communicator& world, const std::exception& e, bool collective, int code,
         const char* prefix) {
  if (world.size() > 1 && !collective) world.abort_all(prefix + std::string(e.what()), code);
  if (world.rank() == 0) std::fprintf(stderr, "fdem: %s%s\n", prefix, e.what());
  return code;
}

int run_command(int argc, char** argv, const fdem::Communicator& world) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::fputs(usage, stderr);
    return exit_bad_input;
  }
  if (args[0] == "--version" || args[0] == "version") {
    std::printf("fdem %s\n", FDEM_VERSION);
    return 0;
  }
  if (args[0] == "--help" || args[0] == "-h") {
    std::fputs(usage, stdout);
    return 0;
  }
  const std::string command = args[0];
  if (command == "prepare") return prepare_command(args, world);
  if (command != "run" && command != "check") {
    std::fprintf(stderr, "fdem: unknown command '%s'\n%s", command.c_str(), usage);
    return exit_bad_input;
  }
  std::string scene_path;
  fdem::RunOptions options;
  std::vector<std::string> overrides;
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&](const char* flag) -> std::string {
      if (i + 1 >= args.size()) {
        std::fprintf(stderr, "fdem: %s needs a value\n%s", flag, usage);
        std::exit(exit_bad_input);
      }
      return args[++i];
    };
    if (a == "-o" || a == "--output")
      options.output_dir = value("-o");
    else if (a == "--set")
      overrides.push_back(value("--set"));
    else if (a.rfind("--set=", 0) == 0)
      overrides.push_back(a.substr(6));
    else if (a == "-q" || a == "--quiet")
      options.quiet = true;
    else if (a == "--restart")
      options.restart_path = value("--restart");
    else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "fdem: unknown option '%s'\n%s", a.c_str(), usage);
      return exit_bad_input;
    } else if (scene_path.empty())
      scene_path = a;
    else {
      std::fprintf(stderr, "fdem: unexpected argument '%s' (one scene per run)\n%s", a.c_str(),
                   usage);
      return exit_bad_input;
    }
  }
  if (scene_path.empty()) {
    std::fprintf(stderr, "fdem: %s needs a scene file\n%s", command.c_str(), usage);
    return exit_bad_input;
  }
  try {
    fdem::Scene scene;
    fdem::mark_phase(fdem::CommPhase::startup);
    world.run_collectively([&] { scene = fdem::read_scene(scene_path, overrides); });
    if (command == "check") return world.rank() == 0 ? check(scene) : 0;
    if (world.rank() != 0) options.quiet = true;
    auto sim = fdem::make_simulation(scene, options, &world);
    const fdem::RunReport report = sim->run();
    if (report.status == "interrupted") {
      if (world.rank() == 0)
        std::fprintf(stderr, "fdem: %s.\nThe last frame and summary.json are in %s.\n",
                     report.reason.c_str(), options.output_dir.c_str());
      return exit_interrupted;
    }
    if (report.status != "completed") {
      if (world.rank() == 0)
        std::fprintf(stderr, "fdem: %s\n%s are in %s.\n", report.reason.c_str(),
                     report.io_failure
                         ? "The frames written and summary.json (when the disk allowed)"
                         : "The last good frame and summary.json",
                     options.output_dir.c_str());
      return report.io_failure ? exit_io_failure : exit_numerical_failure;
    }
    if (!options.quiet && world.rank() == 0 && !report.reason.empty())
      std::fprintf(stderr, "fdem: %s\n", report.reason.c_str());  // e.g. ended at equilibrium
    if (!options.quiet)
      std::fprintf(stderr, "results in %s (open frames.pvd in ParaView)\n",
                   options.output_dir.c_str());
    return 0;
  } catch (const fdem::InputError& e) {
    return fail(world, e, dynamic_cast<const fdem::CollectiveFailure*>(&e) != nullptr,
                exit_bad_input, "error: ");
  } catch (const fdem::NumericalFailure& e) {
    return fail(world, e, dynamic_cast<const fdem::CollectiveFailure*>(&e) != nullptr,
                exit_numerical_failure, "");
  } catch (const fdem::IoError& e) {
    return fail(world, e, dynamic_cast<const fdem::CollectiveFailure*>(&e) != nullptr,
                exit_io_failure, "I/O failure: ");
  } catch (const std::exception& e) {
    return fail(world, e, dynamic_cast<const fdem::CollectiveFailure*>(&e) != nullptr, 1,
                "error: ");
  }
}

// fdem prepare MESH.msh [-o MODEL.h5] [--block-rows N]: the Gmsh file streamed once into a model
// file (parallel/model_file.hpp) that N ranks read slice by slice.  One process does the work.
int prepare_command(const std::vector<std::string>& args, const fdem::Communicator& world) {
  std::string mesh, output;
  fdem::PrepareOptions options;
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool has_value = i + 1 < args.size();
    if ((a == "-o" || a == "--output") && has_value) {
      output = args[++i];
    } else if (a == "--block-rows" && has_value) {
      const std::string& text = args[++i];
      char* end = nullptr;
      options.block_rows = std::strtoll(text.c_str(), &end, 10);
      if (end == text.c_str() || *end != '\0' || options.block_rows < 1) {
        std::fprintf(stderr, "fdem: --block-rows needs a positive integer, found '%s'\n%s",
                     text.c_str(), usage);
        return exit_bad_input;
      }
    } else if (a == "-o" || a == "--output" || a == "--block-rows") {
      std::fprintf(stderr, "fdem: %s needs a value\n%s", a.c_str(), usage);
      return exit_bad_input;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "fdem: unknown option '%s'\n%s", a.c_str(), usage);
      return exit_bad_input;
    } else if (mesh.empty()) {
      mesh = a;
    } else {
      std::fprintf(stderr, "fdem: unexpected argument '%s' (one mesh per prepare)\n%s", a.c_str(),
                   usage);
      return exit_bad_input;
    }
  }
  if (mesh.empty()) {
    std::fprintf(stderr, "fdem: prepare needs a Gmsh mesh file\n%s", usage);
    return exit_bad_input;
  }
  if (output.empty()) {
    const std::size_t dot = mesh.find_last_of('.'), slash = mesh.find_last_of('/');
    output = (dot != std::string::npos && (slash == std::string::npos || dot > slash)
                  ? mesh.substr(0, dot)
                  : mesh) +
             ".h5";
  }
  try {
    fdem::PrepareReport report;
    world.run_collectively([&] {
      if (world.is_root()) report = fdem::prepare_model_file(mesh, output, options);
    });
    if (world.is_root())
      std::printf("%s: %lld nodes, %lld tetrahedra from %s\n", output.c_str(),
                  static_cast<long long>(report.nodes), static_cast<long long>(report.tets),
                  mesh.c_str());
    return 0;
  } catch (const fdem::InputError& e) {
    return fail(world, e, true, exit_bad_input, "error: ");
  } catch (const fdem::IoError& e) {
    return fail(world, e, true, exit_io_failure, "I/O failure: ");
  }
}
