# Precompiled headers for the sanitizer build, whose clean build is most of ./dev test's time on
# two cores (docs/reliability.md, "The test command's duration"). Used where they pay: the vision
# and sim libraries and the tests, whose files are short next to the standard library, Eigen,
# OpenCV and Catch2 headers they read (1-2.4 s saved per file). Elsewhere (fusion, the tools) a
# file's compile is its own code's, and loading the header cost more than it saved. Off in the
# Release build, which compiles every file from its own #includes: a missing #include shows there.
option(EPICHEAD_PCH "Precompile the common library headers (default: on in the sanitizer build)" ${EPICHEAD_SANITIZE})

set(epichead_pch_std <algorithm> <array> <cmath> <cstdint> <cstring> <expected> <filesystem> <fstream>
                     <functional> <limits> <map> <memory> <numbers> <optional> <random> <span> <sstream>
                     <string> <string_view> <utility> <vector>)
set(epichead_pch_eigen <Eigen/Core> <Eigen/Geometry>)
set(epichead_pch_opencv <opencv2/core.hpp> <opencv2/imgproc.hpp>)
set(epichead_pch_catch <catch2/catch.hpp>)

# epichead_precompile(<target> [EIGEN] [OPENCV] [CATCH]): the target's files start from one
# precompiled header of the standard library and the libraries named, which it must use already.
function(epichead_precompile target)
  if(NOT EPICHEAD_PCH)
    return()
  endif()
  cmake_parse_arguments(P "EIGEN;OPENCV;CATCH" "" "" ${ARGN})
  set(headers ${epichead_pch_std})
  foreach(part EIGEN OPENCV CATCH)
    if(P_${part})
      string(TOLOWER ${part} lower)
      list(APPEND headers ${epichead_pch_${lower}})
    endif()
  endforeach()
  target_precompile_headers(${target} PRIVATE ${headers})
  # A header that cannot be used (a file's flags differ) is read as text instead, which only
  # costs time: the build log says so rather than lose the gain unseen.
  target_compile_options(${target} PRIVATE -Winvalid-pch)
endfunction()
