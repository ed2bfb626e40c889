# Runs an MPI test that must end all ranks: passes when mpiexec exits non-zero, within the test's
# timeout, and its output contains EXPECT.
# -D MPIEXEC, NP_FLAG, NP, EXE, FILTER, EXPECT
execute_process(COMMAND ${MPIEXEC} ${NP_FLAG} ${NP} --oversubscribe ${EXE} ${FILTER}
                RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(result EQUAL 0)
  message(FATAL_ERROR "expected a non-zero exit, got 0")
endif()
string(FIND "${out}${err}" "${EXPECT}" found)
if(found EQUAL -1)
  message(FATAL_ERROR "expected the output to contain '${EXPECT}'")
endif()
message("exit code ${result}, message found")
