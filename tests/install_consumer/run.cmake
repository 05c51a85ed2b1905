# Installs the current build into a fresh prefix, builds the consumer project against it and
# runs it. Called by ctest (tests/CMakeLists.txt) with -DBUILD_DIR= -DSOURCE_DIR= -DWORK_DIR=
# -DGENERATOR= and, for a sanitizer build, -DSANITIZE= (its -fsanitize list).
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "install consumer: -D${var}= is required")
  endif()
endforeach()

function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "install consumer: ${what} failed (${rc}):\n${out}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run_step("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# What the package promises is in place.
foreach(file bin/roiflow include/roiflow/core/error.hpp include/roiflow/flow/dense_lk.hpp
             include/roiflow/eval/flo_io.hpp include/roiflow/report/plot.hpp
             include/roiflow/video/video_source.hpp include/roiflow/tracking/tracker.hpp
             include/roiflow/pipeline/frame_graph.hpp)
  if(NOT EXISTS ${prefix}/${file})
    message(FATAL_ERROR "install consumer: ${prefix}/${file} was not installed")
  endif()
endforeach()
file(GLOB_RECURSE config ${prefix}/*/roiflowConfig.cmake)
file(GLOB_RECURSE targets ${prefix}/*/roiflowTargets.cmake)
if(NOT config OR NOT targets)
  message(FATAL_ERROR "install consumer: no roiflowConfig.cmake / roiflowTargets.cmake installed")
endif()
# Build-only flags must not reach consumers.
file(READ ${targets} exported)
foreach(flag -march=native -Wall -fsanitize roiflow_warnings roiflow_native_arch roiflow_sanitizers
             roiflow_build_flags include_roots /work/)
  string(FIND "${exported}" "${flag}" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "install consumer: ${targets} exports '${flag}'")
  endif()
endforeach()

run_step("the installed CLI" ${prefix}/bin/roiflow --help)

# Libraries built with a sanitizer need its runtime in the program that links them: a consumer
# of such a build compiles and links with the same -fsanitize (the package does not impose it).
set(consumer_flags "")
if(SANITIZE)
  set(consumer_flags "-fsanitize=${SANITIZE}")
  if(SANITIZE MATCHES "undefined")
    string(APPEND consumer_flags " -fno-sanitize=vptr")
  endif()
endif()
run_step("configuring the consumer" ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build
         -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix}
         "-DCMAKE_CXX_FLAGS=${consumer_flags}" "-DCMAKE_EXE_LINKER_FLAGS=${consumer_flags}")
run_step("building the consumer" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)
foreach(app flow_consumer pipeline_consumer)
  run_step("running ${app}" ${WORK_DIR}/build/${app})
  message(STATUS "${app}: ${step_output}")
endforeach()
file(REMOVE_RECURSE ${WORK_DIR})
