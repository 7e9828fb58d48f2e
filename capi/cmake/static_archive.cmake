# libsogmm.a: the C API as one static archive, for programs that must run
# without finding libsogmm.so at load time (the Rust crate's `static` feature,
# bindings/rust/README.md). It holds the same objects as libsogmm.so (the C
# API, the core, the format layer and the zstd it needs) partially linked into
# one object; like the shared library's version script, only the sogmm_*
# functions stay global (make_static_archive.cmake says how). A program
# linking it adds the C++ runtime, OpenMP and the image decoders (shared:
# Debian's static libpng and libjpeg are not position-independent):
# -lstdc++ -lgomp -lpng16 -ljpeg -lm.
set(SOGMM_STATIC_ARCHIVE ${CMAKE_CURRENT_BINARY_DIR}/libsogmm.a)
set(_sogmm_whole $<TARGET_FILE:sogmm_core>)
set(_sogmm_extra "")
if(TARGET sogmm_format)
  list(APPEND _sogmm_whole $<TARGET_FILE:sogmm_format>)
  set(_sogmm_extra ${SOGMM_ZSTD_LIBRARY})
endif()
add_custom_command(
  OUTPUT ${SOGMM_STATIC_ARCHIVE}
  COMMAND ${CMAKE_COMMAND}
    -DCXX=${CMAKE_CXX_COMPILER} -DNM=${CMAKE_NM} -DOBJCOPY=${CMAKE_OBJCOPY} -DAR=${CMAKE_AR}
    "-DOBJECTS=$<JOIN:$<TARGET_OBJECTS:sogmm_capi_objects>,|>"
    "-DWHOLE_ARCHIVES=$<JOIN:${_sogmm_whole},|>"
    "-DARCHIVES=${_sogmm_extra}"
    -DOUTPUT=${SOGMM_STATIC_ARCHIVE}
    -P ${CMAKE_CURRENT_SOURCE_DIR}/cmake/make_static_archive.cmake
  DEPENDS sogmm_capi_objects $<TARGET_OBJECTS:sogmm_capi_objects> ${_sogmm_whole} ${CMAKE_CURRENT_SOURCE_DIR}/cmake/make_static_archive.cmake
  COMMENT "Linking the static archive libsogmm.a"
  VERBATIM)
add_custom_target(sogmm_static ALL DEPENDS ${SOGMM_STATIC_ARCHIVE})
