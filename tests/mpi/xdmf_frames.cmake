# The fdem command on RANKS ranks with output.format=xdmf against the same run with .vtu frames:
# the same state_hash, one .h5 per frame (as many as the .pvd lists) and no .vtu piece, and a
# frames.xdmf that names every frame file.
# -D MPIEXEC, NP_FLAG, FDEM, SCENE, WORK, RANKS
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

function(run_fdem out)
  execute_process(COMMAND ${MPIEXEC} ${NP_FLAG} ${RANKS} --oversubscribe ${FDEM} run ${SCENE}
                          -o ${out} -q ${ARGN}
                  RESULT_VARIABLE result OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "fdem on ${RANKS} ranks (${ARGN}) exited with ${result}:\n${stdout}${stderr}")
  endif()
  file(READ ${out}/summary.json summary)
  string(REGEX MATCH "\"state_hash\": \"([0-9a-f]+)\"" _ "${summary}")
  set(hash ${CMAKE_MATCH_1} PARENT_SCOPE)
endfunction()

run_fdem(${WORK}/vtu)
set(vtu_hash ${hash})
run_fdem(${WORK}/xdmf --set output.format=xdmf --set output.mpi_io_hints.romio_cb_write=enable)
if(NOT hash STREQUAL vtu_hash OR hash STREQUAL "")
  message(FATAL_ERROR "state_hash with xdmf frames '${hash}', with vtu frames '${vtu_hash}'")
endif()

file(READ ${WORK}/vtu/frames.pvd pvd)
string(REGEX MATCHALL "<DataSet " vtu_frames "${pvd}")
list(LENGTH vtu_frames n_frames)
file(GLOB h5_files ${WORK}/xdmf/frames/*.h5)
file(GLOB other_files ${WORK}/xdmf/frames/*.vtu ${WORK}/xdmf/frames/*.pvtu ${WORK}/xdmf/frames/*.tmp
     ${WORK}/xdmf/frames.pvd)
list(LENGTH h5_files n_h5)
if(NOT n_h5 EQUAL n_frames OR n_frames LESS 2)
  message(FATAL_ERROR "${n_h5} frame files in ${WORK}/xdmf/frames, the .vtu run wrote ${n_frames}")
endif()
if(other_files)
  message(FATAL_ERROR "the xdmf run wrote other frame files too: ${other_files}")
endif()
file(READ ${WORK}/xdmf/frames.xdmf xdmf)
foreach(h5 ${h5_files})
  get_filename_component(name ${h5} NAME)
  if(NOT xdmf MATCHES "frames/${name}:/tets/connectivity")
    message(FATAL_ERROR "frames.xdmf does not reference frames/${name}")
  endif()
endforeach()
message("xdmf and vtu runs on ${RANKS} ranks: state_hash ${hash}, ${n_h5} frames, 1 .h5 each")
