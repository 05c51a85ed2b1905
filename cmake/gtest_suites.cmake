# One ctest test per GoogleTest suite of a test binary, found when the binary is built.
#
# gtest_discover_tests() makes one ctest test, hence one process, per test case. Every test binary
# links OpenCV, and Debian's libopencv_videoio and libopencv_imgcodecs bring in ~250 shared
# libraries (GStreamer, FFmpeg, GDAL, ...): loading them costs a process ~0.2 s, twice that under
# the sanitizers, which over ~600 test cases was minutes of CI. A suite runs its cases in one
# process instead; ctest still runs suites in parallel, and a failure names its suite, with
# GoogleTest's output naming the case.
#
#   roiflow_add_gtest_suites(<target> LABELS <labels> [ENVIRONMENT <var=value>...])
#
# Each suite becomes the ctest test `<first label>/<suite>` (suite names repeat across parts),
# running `<target> --gtest_filter=<suite>.*`, with the given labels and environment, a timeout
# for the whole suite, and its number of cases as its COST (ctest starts the largest suites first
# when it has no timings yet). ROIFLOW_TEST_FILTER (a GoogleTest filter, e.g. `-A.b:C.*`, set by
# the sanitizer presets) selects the cases: a suite with cases left out lists those it runs.
#
# In script mode (cmake -DEXE=... -DOUT=... -DFILTER=... -P gtest_suites.cmake) it lists the
# binary's cases and writes the add_test() lines to OUT, after checking that the suites' filters
# together select exactly the chosen cases (else the build fails).

if(CMAKE_SCRIPT_MODE_FILE)
  cmake_policy(SET CMP0057 NEW)  # IN_LIST
  string(REPLACE "|" ";" EMULATOR "${EMULATOR}")  # a list (qemu-aarch64;-L;<sysroot>)
  function(list_cases filter out_var)
    set(args --gtest_list_tests)
    if(filter)
      list(APPEND args "--gtest_filter=${filter}")
    endif()
    execute_process(COMMAND ${EMULATOR} ${EXE} ${args} OUTPUT_VARIABLE output
                    RESULT_VARIABLE rc TIMEOUT 120)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "gtest_suites: '${EXE} --gtest_list_tests' failed (${rc}):\n${output}")
    endif()
    # Comments (`# GetParam() = ...`) may hold brackets and semicolons, which CMake lists split on.
    string(REGEX REPLACE "#[^\n]*" "" output "${output}")
    string(REPLACE ";" "" output "${output}")
    string(REPLACE "[" "" output "${output}")
    string(REPLACE "]" "" output "${output}")
    string(REPLACE "\n" ";" lines "${output}")
    set(cases)
    set(suite)
    foreach(line IN LISTS lines)
      if(line MATCHES "^([^ ]+)\\. *$")
        set(suite ${CMAKE_MATCH_1})
      elseif(suite AND line MATCHES "^  +([^ ]+) *$")
        list(APPEND cases "${suite}.${CMAKE_MATCH_1}")
      elseif(NOT line MATCHES "^ *$")
        set(suite)  # gtest_main's banner and the like
      endif()
    endforeach()
    set(${out_var} ${cases} PARENT_SCOPE)
  endfunction()

  list_cases("" all)
  list_cases("${FILTER}" selected)
  # The cases of each suite (all_<suite>) and those the filter chose (selected_<suite>).
  set(suites)
  foreach(case IN LISTS all)
    string(REGEX REPLACE "\\.[^.]*$" "" suite "${case}")
    list(APPEND suites ${suite})
    list(APPEND all_${suite} ${case})
    if(case IN_LIST selected)
      list(APPEND selected_${suite} ${case})
    endif()
  endforeach()
  list(REMOVE_DUPLICATES suites)
  set(content "")
  set(filters)
  foreach(suite IN LISTS suites)
    list(LENGTH all_${suite} n_all)
    list(LENGTH selected_${suite} n)
    if(n EQUAL 0)
      continue()
    elseif(n EQUAL n_all)
      set(filter "${suite}.*")
    else()
      list(JOIN selected_${suite} ":" filter)
    endif()
    list(APPEND filters "${filter}")
    string(APPEND content
           "add_test([==[${PREFIX}/${suite}]==] ${EMULATOR} [==[${EXE}]==] "
           "[==[--gtest_filter=${filter}]==])\n"
           "set_tests_properties([==[${PREFIX}/${suite}]==] PROPERTIES COST ${n})\n"
           "list(APPEND ${LIST_VAR} [==[${PREFIX}/${suite}]==])\n")
  endforeach()
  # The suites' filters together must select exactly the cases chosen: no case lost, none added.
  list(LENGTH selected n_selected)
  list(JOIN filters ":" union)
  set(n_union 0)
  if(union)
    list_cases("${union}" by_suites)
    list(LENGTH by_suites n_union)
  endif()
  if(NOT n_union EQUAL n_selected)
    message(FATAL_ERROR "gtest_suites: ${EXE}: the suites' filters select ${n_union} cases, "
                        "the filter '${FILTER}' ${n_selected}")
  endif()
  file(WRITE "${OUT}" "set(${LIST_VAR})\n${content}")
  return()
endif()

set(ROIFLOW_TEST_FILTER "" CACHE STRING
    "GoogleTest filter applied to every test binary's cases (the sanitizer presets leave some out)")

function(roiflow_add_gtest_suites target)
  cmake_parse_arguments(ARG "" "" "LABELS;ENVIRONMENT" ${ARGN})
  list(GET ARG_LABELS 0 prefix)
  set(dir ${CMAKE_CURRENT_BINARY_DIR}/gtest_suites)
  set(list_file ${dir}/${target}_list.cmake)
  set(include_file ${dir}/${target}_include.cmake)
  set(list_var roiflow_suites_${target})
  # A custom command's arguments split on semicolons.
  string(REPLACE ";" "|" emulator "${CMAKE_CROSSCOMPILING_EMULATOR}")
  # A suite's cases run in one process: 15 minutes, an hour under an emulator (qemu-user).
  set(timeout 900)
  if(CMAKE_CROSSCOMPILING_EMULATOR)
    set(timeout 3600)
  endif()
  # Bracket arguments keep the semicolons: one property value, a list.
  set(properties "TIMEOUT ${timeout} LABELS [==[${ARG_LABELS}]==]")
  if(ARG_ENVIRONMENT)
    string(APPEND properties " ENVIRONMENT [==[${ARG_ENVIRONMENT}]==]")
  endif()
  file(WRITE ${include_file}
       "if(EXISTS [==[${list_file}]==])\n"
       "  include([==[${list_file}]==])\n"
       "  if(${list_var})\n"
       "    set_tests_properties(\${${list_var}} PROPERTIES ${properties})\n"
       "  endif()\n"
       "else()\n"
       "  add_test(${target}_NOT_BUILT ${target}_NOT_BUILT)\n"
       "endif()\n")
  add_custom_command(
    TARGET ${target} POST_BUILD
    COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:${target}> -DOUT=${list_file} -DPREFIX=${prefix}
            -DLIST_VAR=${list_var} "-DFILTER=${ROIFLOW_TEST_FILTER}"
            "-DEMULATOR=${emulator}" -P
            ${PROJECT_SOURCE_DIR}/cmake/gtest_suites.cmake
    BYPRODUCTS ${list_file}
    VERBATIM)
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${include_file})
endfunction()
