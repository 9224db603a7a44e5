# Registers the bounded fuzz runs with ctest: each libFuzzer target runs a fixed number of inputs, what
# 60 s of fuzzing ran on CI's machine (2 cores, other tests beside it). A count, not a time: the
# amount of fuzzing does not shrink on a busy machine, so scripts/dev test can fuzz at the lowest
# CPU priority beside the sanitizer tests, on the CPU they leave idle.
# They are built and run in the tree configured with -DBELLOWS_FUZZ=ON (clang), which scripts/dev
# test makes its AddressSanitizer + UndefinedBehaviorSanitizer tree: the fuzzers share its
# libraries (their objects carry the coverage feedback) instead of a clang tree of their own.
if(NOT BELLOWS_FUZZ)
  return()
endif()
set(BELLOWS_FUZZ_SCALE 1 CACHE STRING "Multiplies every fuzz target's number of runs")
set(fuzz_runs_fuzz_session_readers 200000)
set(fuzz_runs_fuzz_rig_commands 80000)
set(fuzz_runs_fuzz_config_loader 650000)
foreach(target IN ITEMS fuzz_session_readers fuzz_rig_commands fuzz_config_loader)
  math(EXPR runs "${fuzz_runs_${target}} * ${BELLOWS_FUZZ_SCALE}")
  set(extra)
  if(target STREQUAL "fuzz_config_loader")
    set(extra -DSEEDS=${PROJECT_SOURCE_DIR}/tests/fuzz/seeds_config -DDICT=${PROJECT_SOURCE_DIR}/tests/fuzz/config.dict)
  endif()
  add_test(NAME ${target}
           COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DBUILD_DIR=${CMAKE_BINARY_DIR}/fuzz
                   -DBINARY=$<TARGET_FILE:${target}> -DRUNS=${runs} ${extra}
                   -P ${CMAKE_CURRENT_LIST_DIR}/run_fuzz.cmake)
  set_tests_properties(${target} PROPERTIES TIMEOUT 1800 LABELS fuzz)
endforeach()
