# Registers the bounded fuzz runs with ctest: each libFuzzer target fuzzes for BELLOWS_FUZZ_SECONDS.
# They are built and run in the tree configured with -DBELLOWS_FUZZ=ON (clang), which scripts/dev
# test makes its AddressSanitizer + UndefinedBehaviorSanitizer tree: the fuzzers share its
# libraries (their objects carry the coverage feedback) instead of a clang tree of their own.
if(NOT BELLOWS_FUZZ)
  return()
endif()
set(BELLOWS_FUZZ_SECONDS 60 CACHE STRING "How long the fuzz test runs each fuzz target")
foreach(target IN ITEMS fuzz_session_readers fuzz_rig_commands fuzz_config_loader)
  set(extra)
  if(target STREQUAL "fuzz_config_loader")
    set(extra -DSEEDS=${PROJECT_SOURCE_DIR}/tests/fuzz/seeds_config -DDICT=${PROJECT_SOURCE_DIR}/tests/fuzz/config.dict)
  endif()
  add_test(NAME ${target}
           COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DBUILD_DIR=${CMAKE_BINARY_DIR}/fuzz
                   -DBINARY=$<TARGET_FILE:${target}> -DSECONDS=${BELLOWS_FUZZ_SECONDS} ${extra}
                   -P ${CMAKE_CURRENT_LIST_DIR}/run_fuzz.cmake)
  set_tests_properties(${target} PROPERTIES TIMEOUT 1800 LABELS fuzz)
endforeach()
