# Registers the bounded fuzz run with ctest. It builds the fuzz target with clang in its own build
# directory (<build>/fuzz) and runs it for BELLOWS_FUZZ_SECONDS; without clang it is skipped.
# Registered in the plain build only: the sanitizer builds of CI would repeat the same fuzzing.
if(BELLOWS_SANITIZE)
  return()
endif()
set(BELLOWS_FUZZ_SECONDS 60 CACHE STRING "How long the fuzz test runs each fuzz target")
find_program(BELLOWS_CLANGXX NAMES clang++ clang++-14)
add_test(NAME fuzz_session_readers
         COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DBUILD_DIR=${CMAKE_BINARY_DIR}/fuzz
                 -DCLANGXX=${BELLOWS_CLANGXX} -DTARGET=fuzz_session_readers -DSECONDS=${BELLOWS_FUZZ_SECONDS}
                 -P ${CMAKE_CURRENT_LIST_DIR}/run_fuzz.cmake)
set_tests_properties(fuzz_session_readers PROPERTIES TIMEOUT 1800 LABELS fuzz SKIP_REGULAR_EXPRESSION "SKIPPED:")
add_test(NAME fuzz_rig_commands
         COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DBUILD_DIR=${CMAKE_BINARY_DIR}/fuzz
                 -DCLANGXX=${BELLOWS_CLANGXX} -DTARGET=fuzz_rig_commands -DSECONDS=${BELLOWS_FUZZ_SECONDS}
                 -P ${CMAKE_CURRENT_LIST_DIR}/run_fuzz.cmake)
set_tests_properties(fuzz_rig_commands PROPERTIES TIMEOUT 1800 LABELS fuzz SKIP_REGULAR_EXPRESSION "SKIPPED:")
add_test(NAME fuzz_config_loader
         COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DBUILD_DIR=${CMAKE_BINARY_DIR}/fuzz
                 -DCLANGXX=${BELLOWS_CLANGXX} -DTARGET=fuzz_config_loader -DSECONDS=${BELLOWS_FUZZ_SECONDS}
                 -DSEEDS=${PROJECT_SOURCE_DIR}/tests/fuzz/seeds_config -DDICT=${PROJECT_SOURCE_DIR}/tests/fuzz/config.dict
                 -P ${CMAKE_CURRENT_LIST_DIR}/run_fuzz.cmake)
set_tests_properties(fuzz_config_loader PROPERTIES TIMEOUT 1800 LABELS fuzz SKIP_REGULAR_EXPRESSION "SKIPPED:")
