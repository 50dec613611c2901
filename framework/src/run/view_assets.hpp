#pragma once
// The viewer's page and script (framework/view/viewer.html and viewer.js), built into the library as text by
// cmake/embed_text.cmake, so that `redres view` needs no file of its own at run time.

namespace redres::view_assets {

extern const char* const kPage;    //!< viewer.html, with the markers view_html() fills
extern const char* const kScript;  //!< viewer.js

}  // namespace redres::view_assets
