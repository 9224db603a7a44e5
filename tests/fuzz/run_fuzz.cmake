# cmake -DSOURCE_DIR=... -DBUILD_DIR=... -DBINARY=... -DRUNS=... [-DSEEDS=dir -DDICT=file] -P run_fuzz.cmake
# Fuzzes the libFuzzer target BINARY (built with -DBELLOWS_FUZZ=ON, tests/fuzz/fuzz_test.cmake) for
# RUNS inputs, starting from the seeds in SEEDS (default tests/fuzz/seeds) and the corpus grown by
# earlier runs in BUILD_DIR/corpus; a failing input is saved in BUILD_DIR.
if(NOT SEEDS)
  set(SEEDS ${SOURCE_DIR}/tests/fuzz/seeds)
endif()
if(NOT DICT)
  set(DICT ${SOURCE_DIR}/tests/fuzz/session.dict)
endif()
get_filename_component(TARGET ${BINARY} NAME)
file(MAKE_DIRECTORY ${BUILD_DIR}/corpus/${TARGET})
execute_process(
  COMMAND ${BINARY} ${BUILD_DIR}/corpus/${TARGET} ${SEEDS}
          -dict=${DICT} -runs=${RUNS} -max_len=16384 -timeout=10
          -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix=${BUILD_DIR}/
  RESULT_VARIABLE fuzzed)
if(fuzzed)
  message(FATAL_ERROR "${TARGET} found a failing input (exit ${fuzzed}); it is saved in ${BUILD_DIR} "
                      "as crash-* / timeout-* / oom-*; reproduce with: ${BINARY} <file>")
endif()
