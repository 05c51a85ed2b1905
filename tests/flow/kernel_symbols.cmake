# Fails when an object of src/flow/lk_kernels_<isa>.cpp defines a global or weak symbol other
# than its table roiflow::flow::detail::lk_kernels_<isa> (see tests/CMakeLists.txt).
#   cmake -DNM=nm -DOBJECTS=a.o|b.o -P kernel_symbols.cmake
string(REPLACE "|" ";" objects "${OBJECTS}")
set(checked 0)
foreach(object IN LISTS objects)
  if(NOT object MATCHES "lk_kernels_([a-z0-9]+)\\.cpp\\.o$")
    continue()
  endif()
  set(isa ${CMAKE_MATCH_1})
  execute_process(COMMAND ${NM} --defined-only -C ${object} OUTPUT_VARIABLE symbols
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${NM} failed on ${object}")
  endif()
  string(REPLACE "\n" ";" lines "${symbols}")
  foreach(line IN LISTS lines)
    # "<address> <type> <name>": upper-case types are global, V/W/u weak or unique.
    if(line MATCHES "^[0-9a-f]+ ([A-Zuvw]) (.*)$")
      set(type ${CMAKE_MATCH_1})
      set(name "${CMAKE_MATCH_2}")
      # Symbols the compiler adds (DW.ref.__gxx_personality_v0, ASan's ODR indicators, which
      # sanitizer builds emit) are not the kernels' own.
      if(name MATCHES "^(DW\\.ref\\.|__odr_asan|__asan_|__ubsan_|__tsan_)")
        continue()
      endif()
      if(NOT name STREQUAL "roiflow::flow::detail::lk_kernels_${isa}")
        message(FATAL_ERROR "${object} defines '${name}' (type ${type}): "
                            "kernel code must have internal linkage")
      endif()
    endif()
  endforeach()
  math(EXPR checked "${checked} + 1")
endforeach()
if(checked EQUAL 0)
  message(FATAL_ERROR "no lk_kernels_*.cpp object among: ${OBJECTS}")
endif()
message(STATUS "${checked} kernel objects define nothing but their table")
