# Warnings on everywhere; Release optimises.  Targets opt in with fdem_target_options().
option(FDEM_NATIVE "Tune for the build machine (-march=native)" OFF)
# AddressSanitizer + UndefinedBehaviorSanitizer on everything built here (scripts/sanitize.sh).
# float-cast-overflow is not part of -fsanitize=undefined: it checks the float → integer casts.
# Any report stops the program (no recovery), so a test that triggers one fails.
option(FDEM_SANITIZE "Build with ASan + UBSan (including float-cast-overflow)" OFF)
if(FDEM_SANITIZE)
  set(FDEM_SANITIZER_FLAGS -fsanitize=address,undefined,float-cast-overflow
                           -fno-sanitize-recover=all -fno-omit-frame-pointer)
  add_compile_options(${FDEM_SANITIZER_FLAGS})
  add_link_options(${FDEM_SANITIZER_FLAGS})
endif()
set(CMAKE_CXX_FLAGS_RELEASE "-O3 -DNDEBUG")
# -g1 (line tables): what the sanitizers' and the fuzzer's stack traces print; full -g doubled the
# sanitizer build's compile time (20.7 → ~10 min on 2 cores).
set(CMAKE_CXX_FLAGS_RELWITHDEBINFO "-O2 -g1 -DNDEBUG")

# -ffp-contract=off: no a·b + c fused into one rounding where the CPU has FMA (-march=native, the
# AVX2 clones), so every build rounds as the x86-64 baseline does and the kernels written twice
# (one joint and four lanes) give the same bits.
# -Wno-psabi: GCC notes that an AVX vector passed by value has another ABI without AVX; the
# four-lane kernels' helpers (core/lanes.hpp) are inline, and the dispatched kernels take their
# batches by reference, so no vector crosses a call between differently built code.
function(fdem_target_options target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wno-unused-parameter
                                           -Wno-psabi -ffp-contract=off)
  if(FDEM_NATIVE)
    target_compile_options(${target} PRIVATE -march=native)
  endif()
endfunction()

# fdem_folder_library(NAME deps...) : a library from every .cpp in the current folder.
function(fdem_folder_library name)
  file(GLOB _sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  if(_sources)
    add_library(fdem_${name} STATIC ${_sources})
    target_include_directories(fdem_${name} PUBLIC ${PROJECT_SOURCE_DIR})
    target_link_libraries(fdem_${name} PUBLIC ${ARGN})
    fdem_target_options(fdem_${name})
  else()
    add_library(fdem_${name} INTERFACE)
    target_include_directories(fdem_${name} INTERFACE ${PROJECT_SOURCE_DIR})
    target_link_libraries(fdem_${name} INTERFACE ${ARGN})
  endif()
  add_library(fdem::${name} ALIAS fdem_${name})
endfunction()
