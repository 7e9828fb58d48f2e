// The self-contained HTML page of `sogmm view` (bindings/js/viewer, built
// into tools/sogmm/viewer/viewer_page.html and compiled in as a string).
#pragma once

#include <string>

namespace sogmm::tools {

/// The page template: the viewer's script (the JavaScript reader and
/// three.js), with markers @@SOGMM_FILE_NAME@@ and @@SOGMM_MODEL_BASE64@@.
extern const char* const kViewerPage;

/// The page for one model: `bytes` (a .sogmm file, valid or not: the page
/// reads it and shows the reader's verdict) embedded as base64, `name`
/// (HTML-escaped) as its title.
std::string viewer_page(const std::string& bytes, const std::string& name);

}  // namespace sogmm::tools
