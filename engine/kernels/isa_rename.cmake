# Gives the library code compiled into each kernel object a per-level name (cmake -P script,
# run by engine/CMakeLists.txt after the kernel files are compiled).
#
# The project's own functions in kernels/isa_<level>*.cpp live in the inline namespace
# isa_<level> (simd/isa_namespace.h). The inline functions and templates of the libraries they
# call (std::max, std::numeric_limits<float>::infinity, xsimd's batch members, ...) cannot be
# put in a namespace, and whenever the compiler leaves them out of line (always at -O0, at
# -O3 for the larger ones) each object carries a weak copy built with its own flags, under the
# same name as the copies in the other levels' objects and in the baseline code. The linker
# keeps one of them for every caller, so e.g. an AVX-512 copy of an xsimd AVX2 helper could
# serve the AVX2 kernels. Here every such weak function (and the COMDAT group around it) is
# renamed <symbol>.isa_<level>, so each level links only to its own copies; two objects of
# one level (isa_avx2.cpp, isa_avx2_accel.cpp) still share theirs. Data (guard variables,
# inline constants) keeps its name: it holds no instructions and one instance is what the
# language requires. The project's own symbols (_ZN...8streamrt) are not renamed: a project
# function outside its level's namespace is a mistake that
# tests/architecture/check_isa_symbols.py reports.
#
# Variables: NM, OBJCOPY, READELF (tools), OUT_DIR, OBJECTS (the compiled kernel objects).
cmake_minimum_required(VERSION 3.22)
foreach(var NM OBJCOPY READELF OUT_DIR OBJECTS)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "isa_rename.cmake: ${var} is not set")
  endif()
endforeach()
file(MAKE_DIRECTORY "${OUT_DIR}")

# The names of the symbols whose nm type is one of the letters `types`, from nm's output.
function(symbols_of types nm_output out)
  string(REGEX MATCHALL "[0-9a-f]+ [${types}] [^\n]+" lines "${nm_output}")
  list(TRANSFORM lines REPLACE "^[0-9a-f]+ [${types}] " "")
  set(${out} "${lines}" PARENT_SCOPE)
endfunction()

foreach(object IN LISTS OBJECTS)
  get_filename_component(name "${object}" NAME)
  string(REGEX REPLACE "(\\.cpp)?\\.o(bj)?$" "" stem "${name}")
  if(NOT stem MATCHES "^isa_([a-z0-9]+)")
    message(FATAL_ERROR "isa_rename.cmake: ${name} is not a kernels/isa_<level>*.cpp object")
  endif()
  set(suffix ".isa_${CMAKE_MATCH_1}")

  execute_process(COMMAND "${NM}" --defined-only -g "${object}" OUTPUT_VARIABLE symbols RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "isa_rename.cmake: ${NM} failed on ${object}")
  endif()
  execute_process(COMMAND "${READELF}" -g -W "${object}" OUTPUT_VARIABLE groups RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "isa_rename.cmake: ${READELF} failed on ${object}")
  endif()

  # Weak functions ("0000000000000000 W _ZSt3maxIfERKT_S2_S2_") and group signatures
  # ("COMDAT group section [    1] `.group' [_ZSt3maxIfERKT_S2_S2_] contains 1 sections:";
  # constructors and destructors are grouped under a local C5/D5 name).
  symbols_of("Wi" "${symbols}" names)
  symbols_of("VuRDBCGS" "${symbols}" data)
  string(REGEX MATCHALL "\\[[^ \n]+\\] contains" signatures "${groups}")
  foreach(match IN LISTS signatures)
    string(REGEX REPLACE "^\\[([^ \n]+)\\] contains$" "\\1" symbol "${match}")
    if(NOT symbol IN_LIST data)  # a group of data (DW.ref.__gxx_personality_v0, a guard) keeps its name
      list(APPEND names "${symbol}")
    endif()
  endforeach()
  list(REMOVE_DUPLICATES names)

  set(map "")
  foreach(symbol IN LISTS names)
    if(symbol MATCHES "^_ZN[KVRO]*8streamrt")
      continue()  # the project's own: namespaced in the source
    endif()
    string(APPEND map "${symbol} ${symbol}${suffix}\n")
  endforeach()
  set(map_file "${OUT_DIR}/${stem}.renames")
  file(WRITE "${map_file}" "${map}")
  execute_process(COMMAND "${OBJCOPY}" "--redefine-syms=${map_file}" "${object}" "${OUT_DIR}/${stem}.o"
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "isa_rename.cmake: ${OBJCOPY} failed on ${object}")
  endif()
endforeach()
