# One short libFuzzer run (ctest `fuzz_<name>_short`), cmake -P script.
#   -DFUZZER=<executable> -DSEEDS=<seed corpus dir> -DWORK=<scratch dir> -DSECONDS=<n>
# The seed corpus is only read: libFuzzer writes new inputs into the first corpus folder
# given, which is a fresh scratch folder. Fails on a missing/empty seed corpus and on any
# libFuzzer failure (crash, leak, timeout, out-of-memory, sanitizer report).
foreach(v FUZZER SEEDS WORK SECONDS)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "run_fuzzer.cmake: -D${v}=... is required")
  endif()
endforeach()
file(GLOB seeds "${SEEDS}/*")
list(LENGTH seeds n_seeds)
if(n_seeds EQUAL 0)
  message(FATAL_ERROR "${SEEDS}: seed corpus missing or empty (tests/fuzz-corpus/<name>/, real data)")
endif()
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}/corpus" "${WORK}/artifacts")
execute_process(
  COMMAND "${FUZZER}" -max_total_time=${SECONDS} -timeout=30 -rss_limit_mb=2048
          -print_final_stats=1 "-artifact_prefix=${WORK}/artifacts/"
          "${WORK}/corpus" "${SEEDS}"
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE out)
file(WRITE "${WORK}/fuzz.log" "${out}")
string(REGEX MATCH "Done [0-9]+ runs in [0-9]+ second" done "${out}")
string(REGEX MATCH "stat::number_of_executed_units: [0-9]+" units "${out}")
message(STATUS "${FUZZER}: ${n_seeds} seeds, ${done}; ${units}; exit ${rc}; log ${WORK}/fuzz.log")
if(NOT rc EQUAL 0)
  string(LENGTH "${out}" len)
  if(len GREATER 6000)
    math(EXPR start "${len} - 6000")
    string(SUBSTRING "${out}" ${start} 6000 out)
  endif()
  message("${out}")
  file(GLOB crashes "${WORK}/artifacts/*")
  message(FATAL_ERROR "fuzzer failed (exit ${rc}); reproducer(s): ${crashes}")
endif()
