# Gids above 2^32: runs the fdem command on a scene with parallel.gid_offset set (every node, tet
# and joint gid = offset + its index) on several rank counts and passes when every run gives the
# state_hash, counts and broken joints of the first run (the hash covers gid − offset, so it does
# not depend on the offset) and reports gids that really start at the offset (summary.json →
# gids: the largest node, tet and joint gid held = offset + count − 1, so none was narrowed or
# lost).  With RESTARTS, continues the earliest checkpoint of the run CHECKPOINT_OF on each
# "ranks:offset" of the list (another offset included: checkpoint rows are gid − offset) and
# requires the same hash again.
# -D MPIEXEC, NP_FLAG, FDEM, SCENE, WORK,
#    RUNS (list of ranks:offset; the first is the reference), RESTARTS (list, optional),
#    CHECKPOINT_OF (ranks:offset of a run in RUNS, with RESTARTS), ARGS (list, optional)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

function(run_fdem ranks offset out)
  execute_process(COMMAND ${MPIEXEC} ${NP_FLAG} ${ranks} --oversubscribe ${FDEM} run ${SCENE}
                          -o ${out} -q --set parallel.gid_offset=${offset} ${ARGS} ${ARGN}
                  RESULT_VARIABLE result OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "fdem on ${ranks} ranks, gid offset ${offset} (${ARGN}) exited with "
                        "${result}:\n${stdout}${stderr}")
  endif()
  set(run_stderr "${stderr}" PARENT_SCOPE)
endfunction()

# The hash with the counts that must agree; checks the gids the run reports against `offset`.
function(read_run out offset variable)
  file(READ ${out}/summary.json summary)
  string(REGEX MATCH "\"state_hash\": \"([0-9a-f]+)\"" _ "${summary}")
  set(hash ${CMAKE_MATCH_1})
  foreach(count broken_joints fragments elements nodes joints)
    string(REGEX MATCH "\"${count}\": ([0-9]+)" _ "${summary}")
    set(value "${CMAKE_MATCH_1}")  # (if MATCHES below resets CMAKE_MATCH_1)
    if(NOT value MATCHES "^[0-9]+$")
      message(FATAL_ERROR "${out}/summary.json has no ${count}")
    endif()
    set(${count} ${value})
    string(APPEND hash "/${count}=${value}")
  endforeach()
  string(REGEX MATCH "\"gids\": {\"offset\": ([0-9]+), \"node_max\": (-?[0-9]+), \"tet_max\": (-?[0-9]+), \"joint_max\": (-?[0-9]+)}"
         _ "${summary}")
  if(NOT CMAKE_MATCH_1 STREQUAL offset)
    message(FATAL_ERROR "${out}: gids.offset '${CMAKE_MATCH_1}', expected ${offset}")
  endif()
  math(EXPR node_max "${offset} + ${nodes} - 1")
  math(EXPR tet_max "${offset} + ${elements} - 1")
  if(joints GREATER 0)
    math(EXPR joint_max "${offset} + ${joints} - 1")
  else()
    set(joint_max -1)
  endif()
  if(NOT CMAKE_MATCH_2 STREQUAL node_max OR NOT CMAKE_MATCH_3 STREQUAL tet_max
     OR NOT CMAKE_MATCH_4 STREQUAL joint_max)
    message(FATAL_ERROR "${out}: largest gids node ${CMAKE_MATCH_2}, tet ${CMAKE_MATCH_3}, joint "
                        "${CMAKE_MATCH_4}; expected ${node_max}, ${tet_max}, ${joint_max}")
  endif()
  message("${out}: state_hash ${hash}, largest tet gid ${CMAKE_MATCH_3}")
  set(${variable} ${hash} PARENT_SCOPE)
endfunction()

set(reference "")
foreach(run ${RUNS})
  string(REPLACE ":" ";" parts ${run})
  list(GET parts 0 ranks)
  list(GET parts 1 offset)
  set(out ${WORK}/ranks${ranks}_offset${offset})
  run_fdem(${ranks} ${offset} ${out})
  read_run(${out} ${offset} hash)
  if(reference STREQUAL "")
    set(reference ${hash})
  elseif(NOT hash STREQUAL reference)
    message(FATAL_ERROR "${ranks} ranks, gid offset ${offset}: ${hash}, expected ${reference}")
  endif()
endforeach()

if(RESTARTS)
  string(REPLACE ":" ";" parts ${CHECKPOINT_OF})
  list(GET parts 0 ranks)
  list(GET parts 1 written_with)
  file(GLOB checkpoints ${WORK}/ranks${ranks}_offset${written_with}/checkpoint_*.h5)
  list(SORT checkpoints)
  list(LENGTH checkpoints count)
  if(count EQUAL 0)
    message(FATAL_ERROR "the run ${CHECKPOINT_OF} wrote no checkpoint")
  endif()
  list(GET checkpoints 0 earliest)
  foreach(run ${RESTARTS})
    string(REPLACE ":" ";" parts ${run})
    list(GET parts 0 ranks)
    list(GET parts 1 offset)
    set(out ${WORK}/restart${ranks}_offset${offset})
    run_fdem(${ranks} ${offset} ${out} --restart ${earliest})
    read_run(${out} ${offset} hash)
    if(NOT hash STREQUAL reference)
      message(FATAL_ERROR "restart from ${earliest} on ${ranks} ranks, gid offset ${offset}: "
                          "${hash}, uninterrupted ${reference}")
    endif()
    # Another offset continues the same state, and says so.
    if(NOT offset STREQUAL written_with AND NOT run_stderr MATCHES "parallel.gid_offset: the checkpoint was written with ${written_with}, this run uses ${offset}")
      message(FATAL_ERROR "restart with gid offset ${offset} from a checkpoint written with "
                          "${written_with}: no warning on stderr:\n${run_stderr}")
    endif()
  endforeach()
endif()
message("all runs: state_hash ${reference}")
