# Runs the fdem command on N ranks and passes when it exits non-zero within the test's timeout
# and its output contains every string of EXPECT (a list).
# -D MPIEXEC, NP_FLAG, NP, FDEM, SCENE, WORK, EXPECT (list), ARGS (list, optional)
file(REMOVE_RECURSE ${WORK})
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
