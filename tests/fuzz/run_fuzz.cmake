# cmake -DSOURCE_DIR=... -DBUILD_DIR=... -DCLANGXX=... -DTARGETS=a,b -DMODE=build -P run_fuzz.cmake
# cmake -DSOURCE_DIR=... -DBUILD_DIR=... -DCLANGXX=... -DTARGETS=a -DMODE=run -DSECONDS=... [-DSEEDS=dir -DDICT=file]
#       -P run_fuzz.cmake
# build: configures and builds the clang + libFuzzer + ASan/UBSan build of TARGETS (once, for all).
# run: fuzzes the built target for SECONDS, starting from the seeds in SEEDS (default
# tests/fuzz/seeds) and the corpus grown by earlier runs.
if(NOT SEEDS)
  set(SEEDS ${SOURCE_DIR}/tests/fuzz/seeds)
endif()
if(NOT DICT)
  set(DICT ${SOURCE_DIR}/tests/fuzz/session.dict)
endif()
if(NOT CLANGXX OR NOT EXISTS "${CLANGXX}")
  message("SKIPPED: clang++ not found; scripts/setup.sh installs it")
  return()
endif()
string(REPLACE "," ";" TARGETS "${TARGETS}")
if(MODE STREQUAL "build")
  # A fuzz tree configured by an older bellows with another generator: configure it afresh (the
  # corpus beside it stays).
  if(EXISTS ${BUILD_DIR}/CMakeCache.txt)
    file(STRINGS ${BUILD_DIR}/CMakeCache.txt generator REGEX "^CMAKE_GENERATOR:INTERNAL=")
    if(NOT generator STREQUAL "CMAKE_GENERATOR:INTERNAL=Ninja")
      file(REMOVE_RECURSE ${BUILD_DIR}/CMakeCache.txt ${BUILD_DIR}/CMakeFiles)
    endif()
  endif()
  # Release: the sanitizer build's -O1 (CMakeLists.txt); line tables name the line of a crash.
  execute_process(
    COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${BUILD_DIR} -G Ninja -DCMAKE_CXX_COMPILER=${CLANGXX}
            -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS=-gline-tables-only -DBELLOWS_FUZZ=ON
            -DBELLOWS_BUILD_TESTS=OFF -DBELLOWS_BUILD_BENCH=OFF -DBELLOWS_SANITIZE=address,undefined
    RESULT_VARIABLE configured OUTPUT_QUIET)
  if(configured)
    message(FATAL_ERROR "configuring the fuzz build in ${BUILD_DIR} failed")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target ${TARGETS} RESULT_VARIABLE built)
  if(built)
    message(FATAL_ERROR "building ${TARGETS} failed")
  endif()
  return()
endif()
set(TARGET ${TARGETS})
file(MAKE_DIRECTORY ${BUILD_DIR}/corpus/${TARGET})
set(binary ${BUILD_DIR}/tests/fuzz/${TARGET})
if(NOT EXISTS ${binary})
  message(FATAL_ERROR "${binary} was not built: the fuzz_build test builds it")
endif()
execute_process(
  COMMAND ${binary} ${BUILD_DIR}/corpus/${TARGET} ${SEEDS}
          -dict=${DICT} -max_total_time=${SECONDS} -max_len=16384 -timeout=10
          -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix=${BUILD_DIR}/
  RESULT_VARIABLE fuzzed)
if(fuzzed)
  message(FATAL_ERROR "${TARGET} found a failing input (exit ${fuzzed}); it is saved in ${BUILD_DIR} "
                      "as crash-* / timeout-* / oom-*; reproduce with: ${binary} <file>")
endif()
