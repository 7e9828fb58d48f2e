# Builds libsogmm.a (run by static_archive.cmake with cmake -P):
#  1. partial link (-r) of the C API objects with the whole core and format
#     archives and the members of the other archives (zstd) they use;
#  2. every strong global symbol except sogmm_* made local, so that the
#     library's C++ internals and its zstd cannot clash with a program's own.
#     Weak symbols (inline functions and templates, e.g. std::string's) stay
#     weak: a program with the same COMDAT group keeps one copy, and a local
#     copy would point into the group the linker discards;
#  3. debug information stripped, as in the shipped libsogmm.so.
# Arguments: CXX NM OBJCOPY AR OUTPUT, and OBJECTS / WHOLE_ARCHIVES joined by '|'.
string(REPLACE "|" ";" objects "${OBJECTS}")
string(REPLACE "|" ";" whole "${WHOLE_ARCHIVES}")
set(combined ${OUTPUT}.combined.o)
set(localized ${OUTPUT}.o)
execute_process(COMMAND ${CXX} -r -nostdlib -o ${combined} ${objects}
    -Wl,--whole-archive ${whole} -Wl,--no-whole-archive ${ARCHIVES}
  COMMAND_ERROR_IS_FATAL ANY)

execute_process(COMMAND ${NM} -g --defined-only ${combined} OUTPUT_VARIABLE symbols
  COMMAND_ERROR_IS_FATAL ANY)
string(REPLACE "\n" ";" lines "${symbols}")
set(hide "")
foreach(line IN LISTS lines)
  # "<address> <type> <name>": T/D/B/R/C are strong definitions. (The name
  # is copied before the second match, which resets CMAKE_MATCH_1.)
  if(line MATCHES "^[0-9a-fA-F]* [TDBRC] (.+)$")
    set(name "${CMAKE_MATCH_1}")
    if(NOT name MATCHES "^sogmm_")
      string(APPEND hide "${name}\n")
    endif()
  endif()
endforeach()
file(WRITE ${OUTPUT}.localize "${hide}")
execute_process(COMMAND ${OBJCOPY} --localize-symbols=${OUTPUT}.localize --strip-debug
  ${combined} ${localized} COMMAND_ERROR_IS_FATAL ANY)

file(REMOVE ${OUTPUT} ${combined} ${OUTPUT}.localize)
execute_process(COMMAND ${AR} rcs ${OUTPUT} ${localized} COMMAND_ERROR_IS_FATAL ANY)
file(REMOVE ${localized})
