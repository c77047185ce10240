# Writes OUTPUT, a C++ file holding the view page (WEB_DIR/viewer.html, viewer.js) as raw
# string literals, and where three.js is (THREE_JS), for spindle view (run at build time
# by apps/CMakeLists.txt: cmake -DWEB_DIR=.. -DTHREE_JS=.. -DOUTPUT=.. -P embed_web.cmake).
set(delimiter "spindle_web")
foreach(name html js)
  if(name STREQUAL "html")
    file(READ ${WEB_DIR}/viewer.html text)
  else()
    file(READ ${WEB_DIR}/viewer.js text)
  endif()
  string(FIND "${text}" ")${delimiter}\"" clash)
  if(NOT clash EQUAL -1)
    message(FATAL_ERROR "${WEB_DIR}: a page file contains the raw-string delimiter )${delimiter}\"")
  endif()
  set(${name}_text "${text}")
endforeach()
file(WRITE ${OUTPUT} "// Generated from apps/spindle/web by apps/embed_web.cmake; do not edit.
#include \"view_server.hpp\"

namespace spindle::app {

ViewAssets view_assets() {
    return {R\"${delimiter}(${html_text})${delimiter}\",
            R\"${delimiter}(${js_text})${delimiter}\",
            \"${THREE_JS}\"};
}

}  // namespace spindle::app
")
