# Runs the fdem command on a scene with each rank count of RANKS and passes when every run
# completes, summary.json's state_hash (and joint_strength hash, when the scene has joints) is the
# same in all of them and bodies.csv (and histories.csv, when the scene writes one) is the same
# file, byte for byte.  With RESTART_RANKS, also continues the first run's earliest checkpoint on
# each of those rank counts and requires the same hash again (checkpoint-and-restart vs.
# uninterrupted), and the uninterrupted run's bodies.csv (histories.csv) rows at the times both
# runs wrote.  With START, every run on more than one rank must report that start-up in
# summary.json (decomposition.start: "distributed" when no rank held the whole model,
# "whole_model").
# -D MPIEXEC, NP_FLAG, FDEM, SCENE, WORK, RANKS (list), RESTART_RANKS (list, optional),
#    START (optional)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

function(run_fdem ranks out)
  execute_process(COMMAND ${MPIEXEC} ${NP_FLAG} ${ranks} --oversubscribe ${FDEM} run ${SCENE}
                          -o ${out} -q ${ARGN}
                  RESULT_VARIABLE result OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "fdem on ${ranks} ranks (${ARGN}) exited with ${result}:\n${stdout}${stderr}")
  endif()
endfunction()

# The state hash, with the counts that must agree too (broken joints, fragments, elements).
function(read_hash out variable ranks)
  file(READ ${out}/summary.json summary)
  string(REGEX MATCH "\"state_hash\": \"([0-9a-f]+)\"" _ "${summary}")
  set(hash ${CMAKE_MATCH_1})
  foreach(count broken_joints fragments elements nodes)
    string(REGEX MATCH "\"${count}\": ([0-9]+)" _ "${summary}")
    set(value "${CMAKE_MATCH_1}")
    if(NOT value MATCHES "^[0-9]+$")
      message(FATAL_ERROR "${out}/summary.json has no ${count}")
    endif()
    string(APPEND hash "/${count}=${value}")
  endforeach()
  # The joints' strengths as drawn (a strength distribution: keyed by joint gid).
  string(REGEX MATCH "\"joint_strength\": {[^}]*\"hash\": \"([0-9a-f]+)\"" _ "${summary}")
  if(CMAKE_MATCH_1)
    string(APPEND hash "/joint_strength=${CMAKE_MATCH_1}")
  endif()
  string(REGEX MATCH "\"migrated_elements\": ([0-9]+)" _ "${summary}")
  set(migrated "${CMAKE_MATCH_1}")
  string(REGEX MATCH "\"start\": \"([a-z_]+)\"" _ "${summary}")
  set(start "${CMAKE_MATCH_1}")
  if(START AND ranks GREATER 1 AND NOT start STREQUAL START)
    message(FATAL_ERROR "${out}: start-up '${start}', expected '${START}'")
  endif()
  message("${out}: state_hash ${hash}, migrated elements ${migrated}, start ${start}")
  set(${variable} ${hash} PARENT_SCOPE)
endfunction()

# CSV file `name` of `out` must be the bytes of `reference_out`'s.
function(compare_csv name out reference_out)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${out}/${name}
                          ${reference_out}/${name} RESULT_VARIABLE different)
  if(different)
    message(FATAL_ERROR "${out}/${name} differs from ${reference_out}/${name}")
  endif()
endfunction()

# Every row of a restarted run's CSV file `name` at a time the uninterrupted run wrote must be
# that run's row, byte for byte (the restart also writes a frame at the checkpoint's time).
function(compare_restarted_rows name out reference_out)
  file(READ ${reference_out}/${name} reference_text)
  file(STRINGS ${out}/${name} rows)
  list(REMOVE_AT rows 0)  # the header
  set(compared 0)
  foreach(row ${rows})
    string(REGEX MATCH "^[^,]*," time "${row}")
    string(FIND "${reference_text}" "\n${time}" at_time)
    if(at_time EQUAL -1)
      continue()
    endif()
    string(FIND "${reference_text}" "\n${row}\n" found)
    if(found EQUAL -1)
      message(FATAL_ERROR "${out}/${name}: row '${row}' is not in ${reference_out}/${name}")
    endif()
    math(EXPR compared "${compared} + 1")
  endforeach()
  if(compared EQUAL 0)
    message(FATAL_ERROR "${out}/${name} has no row at a time of ${reference_out}/${name}")
  endif()
endfunction()

set(reference "")
foreach(ranks ${RANKS})
  run_fdem(${ranks} ${WORK}/ranks${ranks})
  read_hash(${WORK}/ranks${ranks} hash ${ranks})
  if(reference STREQUAL "")
    set(reference ${hash})
    set(first_run ${WORK}/ranks${ranks})
  elseif(NOT hash STREQUAL reference)
    message(FATAL_ERROR "state_hash on ${ranks} ranks is ${hash}, expected ${reference}")
  else()
    compare_csv(bodies.csv ${WORK}/ranks${ranks} ${first_run})
    if(EXISTS ${first_run}/histories.csv)
      compare_csv(histories.csv ${WORK}/ranks${ranks} ${first_run})
    endif()
  endif()
endforeach()

if(RESTART_RANKS)
  file(GLOB checkpoints ${first_run}/checkpoint_*.h5)
  list(SORT checkpoints)
  list(LENGTH checkpoints count)
  if(count EQUAL 0)
    message(FATAL_ERROR "the first run wrote no checkpoint")
  endif()
  list(GET checkpoints 0 earliest)
  foreach(ranks ${RESTART_RANKS})
    run_fdem(${ranks} ${WORK}/restart${ranks} --restart ${earliest})
    read_hash(${WORK}/restart${ranks} hash ${ranks})
    if(NOT hash STREQUAL reference)
      message(FATAL_ERROR "restart from ${earliest} on ${ranks} ranks: state_hash ${hash}, "
                          "uninterrupted ${reference}")
    endif()
    compare_restarted_rows(bodies.csv ${WORK}/restart${ranks} ${first_run})
    if(EXISTS ${first_run}/histories.csv)
      compare_restarted_rows(histories.csv ${WORK}/restart${ranks} ${first_run})
    endif()
  endforeach()
endif()
if(EXISTS ${first_run}/histories.csv)
  message("all runs: state_hash ${reference}, bodies.csv and histories.csv the same")
else()
  message("all runs: state_hash ${reference}, bodies.csv the same")
endif()
