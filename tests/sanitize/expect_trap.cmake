# cmake -DPROGRAM=<exe> -DVALUE=<arg> -DEXPECT=trap|pass -P expect_trap.cmake
# Runs PROGRAM VALUE. EXPECT=trap: it must exit non-zero (or die on a signal) with UBSan's
# float-cast-overflow report and not print its result; EXPECT=pass: it must exit 0 and print it.
execute_process(COMMAND ${PROGRAM} ${VALUE} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(report "runtime error: .* is outside the range of representable values of type 'int'")
if(EXPECT STREQUAL "trap")
  if(rc EQUAL 0 OR out MATCHES "cast .* to" OR NOT err MATCHES "${report}")
    message(FATAL_ERROR "${PROGRAM} ${VALUE} was not stopped by the sanitizer (exit ${rc})\n"
                        "stdout: ${out}\nstderr: ${err}")
  endif()
  message(STATUS "${PROGRAM} ${VALUE}: stopped (exit ${rc})")
elseif(EXPECT STREQUAL "pass")
  if(NOT rc EQUAL 0 OR NOT out MATCHES "cast ${VALUE} to")
    message(FATAL_ERROR "${PROGRAM} ${VALUE} failed (exit ${rc})\nstdout: ${out}\nstderr: ${err}")
  endif()
else()
  message(FATAL_ERROR "EXPECT must be trap or pass")
endif()
