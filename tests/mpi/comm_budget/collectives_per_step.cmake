# Blocking collectives per time step: runs the fdem command on RANKS ranks with the PMPI
# interposer preloaded (comm_budget_interposer.cpp counts, per run phase, the blocking collectives
# each rank calls) and checks the step phase against the step's design (drivers/simulation_step):
#   - one blocking reduction per step (energy terms and flags together), plus one before the first
#     step (is a contact detection due anywhere);
#   - broken joints are told to the ranks that hold their tets by a neighbour-only exchange (no
#     blocking collective); only the first break in a body is gathered by every rank (one
#     allgatherv: a count gather and the rows, two collectives), so at most 2 more per body of
#     the scene (BODIES), however many joints break.
# Redistribution, output and checkpoints are phases of their own, not steps.
# -D MPIEXEC, NP_FLAG, FDEM, INTERPOSER, SCENE, RANKS, BODIES, WORK
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
if(joints GREATER 0)
  math(EXPR limit "${steps} + 1 + 2 * ${BODIES}")
else()
  math(EXPR limit "${steps} + 1")
endif()
foreach(file ${files})
  file(READ ${file} json)
  string(JSON coll GET "${json}" phases step blocking_collectives)
  string(JSON by_call GET "${json}" phases step by_call)
  message(STATUS "${file}: ${coll} blocking collectives in ${steps} steps (${broken} joints broke; "
                 "limit ${limit}): ${by_call}")
  if(coll GREATER limit)
    message(FATAL_ERROR "${file}: ${coll} blocking collectives in ${steps} steps, more than ${limit}"
                        " (one per step, one before the first, two per body that cracks): "
                        "${by_call}")
  endif()
  if(joints GREATER 0 AND broken LESS 10)
    message(FATAL_ERROR "only ${broken} joints broke: too few to show what a break costs")
  endif()
  if(steps LESS 100)
    message(FATAL_ERROR "the scene ran only ${steps} steps: too few to count per step")
  endif()
endforeach()
