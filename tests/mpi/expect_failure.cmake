# Runs the fdem command on N ranks and passes when it exits non-zero within the test's timeout
# and its output contains every string of EXPECT (a list).
# -D MPIEXEC, NP_FLAG, NP, FDEM, SCENE, WORK, EXPECT (list), ARGS (list, optional),
#    RESTART_FROM (optional: a scene run first on one rank; the run under test restarts from its
#    earliest checkpoint), FIRST_ARGS (list, optional: for that first run)
file(REMOVE_RECURSE ${WORK})
if(RESTART_FROM)
  execute_process(COMMAND ${MPIEXEC} ${NP_FLAG} 1 ${FDEM} run ${RESTART_FROM} -o ${WORK}-first -q
                          ${FIRST_ARGS}
                  RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  file(GLOB checkpoints ${WORK}-first/checkpoint_*.h5)
  list(SORT checkpoints)
  if(NOT result EQUAL 0 OR NOT checkpoints)
    message(FATAL_ERROR "the first run (${RESTART_FROM}) wrote no checkpoint:\n${out}${err}")
  endif()
  list(GET checkpoints 0 earliest)
  list(APPEND ARGS --restart ${earliest})
endif()
execute_process(COMMAND ${MPIEXEC} ${NP_FLAG} ${NP} --oversubscribe ${FDEM} run ${SCENE} -o ${WORK}
                        -q ${ARGS}
                RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(result EQUAL 0)
  message(FATAL_ERROR "expected a non-zero exit, got 0")
endif()
foreach(text ${EXPECT})
  string(FIND "${out}${err}" "${text}" found)
  if(found EQUAL -1)
    message(FATAL_ERROR "expected the output to contain '${text}'")
  endif()
endforeach()
message("exit code ${result}, messages found")
