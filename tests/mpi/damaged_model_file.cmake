# A damaged model file read on N ranks: `fdem prepare` makes a good one, damage_model_file damages
# a copy (MODE), and `fdem run` on NP ranks with the scene's body 0 reading the copy must end every
# rank within the test's timeout with exit code 2 and output containing every string of EXPECT.
# -D MPIEXEC, NP_FLAG, NP, FDEM, DAMAGE, SCENE, MESH, WORK, MODE, EXPECT (list)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${FDEM} prepare ${MESH} -o ${WORK}/good.h5 RESULT_VARIABLE result
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "fdem prepare failed (${result}):\n${out}${err}")
endif()
execute_process(COMMAND ${DAMAGE} ${WORK}/good.h5 ${WORK}/bad.h5 ${MODE} RESULT_VARIABLE result
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "damage_model_file failed (${result}):\n${out}${err}")
endif()
execute_process(COMMAND ${MPIEXEC} ${NP_FLAG} ${NP} --oversubscribe ${FDEM} run ${SCENE}
                        -o ${WORK}/run -q --set bodies.0.mesh.file=${WORK}/bad.h5
                TIMEOUT 50 RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT result STREQUAL "2")
  message(FATAL_ERROR "expected exit code 2 (bad input) on every rank, got '${result}'")
endif()
foreach(text ${EXPECT})
  string(FIND "${out}${err}" "${text}" found)
  if(found EQUAL -1)
    message(FATAL_ERROR "expected the output to contain '${text}'")
  endif()
endforeach()
message("exit code 2, messages found")
