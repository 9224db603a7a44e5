# Registers the bounded fuzz runs with ctest. One setup test builds every fuzz target with clang in
# its own build directory (<build>/fuzz); each target then fuzzes for BELLOWS_FUZZ_SECONDS. Without
# clang they are skipped. Registered in the plain build only: the sanitizer builds of CI would
# repeat the same fuzzing.
if(BELLOWS_SANITIZE)
  return()
endif()
set(BELLOWS_FUZZ_SECONDS 60 CACHE STRING "How long the fuzz test runs each fuzz target")
find_program(BELLOWS_CLANGXX NAMES clang++ clang++-14)
set(fuzz_targets fuzz_session_readers fuzz_rig_commands fuzz_config_loader)
string(JOIN "," fuzz_target_names ${fuzz_targets})  # one argument: a list would be split
set(fuzz_common -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DBUILD_DIR=${CMAKE_BINARY_DIR}/fuzz -DCLANGXX=${BELLOWS_CLANGXX})

add_test(NAME fuzz_build COMMAND ${CMAKE_COMMAND} ${fuzz_common} -DTARGETS=${fuzz_target_names} -DMODE=build
                                 -P ${CMAKE_CURRENT_LIST_DIR}/run_fuzz.cmake)
set_tests_properties(fuzz_build PROPERTIES TIMEOUT 1800 LABELS fuzz FIXTURES_SETUP fuzz_targets
                                           SKIP_REGULAR_EXPRESSION "SKIPPED:")

foreach(target IN LISTS fuzz_targets)
  set(extra)
  if(target STREQUAL "fuzz_config_loader")
    set(extra -DSEEDS=${PROJECT_SOURCE_DIR}/tests/fuzz/seeds_config -DDICT=${PROJECT_SOURCE_DIR}/tests/fuzz/config.dict)
  endif()
  add_test(NAME ${target}
           COMMAND ${CMAKE_COMMAND} ${fuzz_common} -DTARGETS=${target} -DMODE=run -DSECONDS=${BELLOWS_FUZZ_SECONDS} ${extra}
                   -P ${CMAKE_CURRENT_LIST_DIR}/run_fuzz.cmake)
  set_tests_properties(${target} PROPERTIES TIMEOUT 1800 LABELS fuzz FIXTURES_REQUIRED fuzz_targets
                                            SKIP_REGULAR_EXPRESSION "SKIPPED:")
endforeach()
