# Turns the built viewer page (viewer_page.html, committed; rebuilt from
# bindings/js by `npm run build-viewer`) into a C++ source file holding it as
# a string, so that `sogmm view` needs no file beside the executable.
# cmake -DIN=viewer_page.html -DOUT=viewer_page.cpp -P embed_page.cmake
file(READ ${IN} page)
string(FIND "${page}" ")sogmm_page\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${IN} contains the raw string delimiter")
endif()
# Raw string pieces of at most 60000 characters (some compilers limit one literal).
string(LENGTH "${page}" n)
set(pieces "")
set(at 0)
while(at LESS n)
  string(SUBSTRING "${page}" ${at} 60000 piece)
  string(APPEND pieces "R\"sogmm_page(${piece})sogmm_page\"\n")
  math(EXPR at "${at} + 60000")
endwhile()
file(WRITE ${OUT}.tmp "// Generated from ${IN} by embed_page.cmake: do not edit.\n#include \"viewer_page.hpp\"\n\nnamespace sogmm::tools {\nconst char* const kViewerPage =\n${pieces};\n}  // namespace sogmm::tools\n")
file(RENAME ${OUT}.tmp ${OUT})
