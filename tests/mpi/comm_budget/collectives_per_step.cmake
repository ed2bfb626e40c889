# Blocking collectives per time step: runs the fdem command on RANKS ranks with the PMPI
# interposer preloaded (comm_budget_interposer.cpp counts, per run phase, the blocking collectives
# each rank calls) and checks the step phase against the step's design (drivers/simulation_step):
#   - one blocking reduction per step (energy terms and flags together), plus one before the first
#     step (is a contact detection due anywhere);
#   - a step that follows broken joints also gathers their records (one allgatherv: a count
#     gather and the rows, two collectives), so at most 2 more per broken joint;
#   - never more than two per step on average in a joint scene, one in any other.
# Redistribution, output and checkpoints are phases of their own, not steps.
# -D MPIEXEC, NP_FLAG, FDEM, INTERPOSER, SCENE, RANKS, WORK
cmake_minimum_required(VERSION 3.20)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/budget)
execute_process(COMMAND ${MPIEXEC} ${NP_FLAG} ${RANKS} --oversubscribe ${CMAKE_COMMAND} -E env
                        LD_PRELOAD=${INTERPOSER} FDEM_COMM_BUDGET_OUT=${WORK}/budget ${FDEM} run
                        ${SCENE} -o ${WORK}/run -q
                RESULT_VARIABLE result OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "fdem on ${RANKS} ranks exited with ${result}:\n${stdout}${stderr}")
endif()
file(READ ${WORK}/run/summary.json summary)
string(JSON steps GET "${summary}" steps)
string(JSON broken GET "${summary}" broken_joints)
string(JSON joints GET "${summary}" joints)
file(GLOB files ${WORK}/budget/rank*.json)
list(LENGTH files count)
if(NOT count EQUAL RANKS)
  message(FATAL_ERROR "${count} counter files for ${RANKS} ranks (is ${INTERPOSER} preloaded?)")
endif()
math(EXPR limit "${steps} + 1 + 2 * ${broken}")
if(joints GREATER 0)
  math(EXPR average_limit "2 * ${steps}")
else()
  math(EXPR average_limit "${steps} + 1")
endif()
if(average_limit LESS limit)
  set(limit ${average_limit})
endif()
foreach(file ${files})
  file(READ ${file} json)
  string(JSON coll GET "${json}" phases step blocking_collectives)
  string(JSON by_call GET "${json}" phases step by_call)
  message(STATUS "${file}: ${coll} blocking collectives in ${steps} steps (${broken} joints broke; "
                 "limit ${limit}): ${by_call}")
  if(coll GREATER limit)
    message(FATAL_ERROR "${file}: ${coll} blocking collectives in ${steps} steps, more than ${limit}"
                        " (one per step, one before the first, two per broken joint, at most "
                        "two per step with joints): ${by_call}")
  endif()
  if(steps LESS 100)
    message(FATAL_ERROR "the scene ran only ${steps} steps: too few to count per step")
  endif()
endforeach()
