#pragma once

namespace hila::viz {

// The report page's scripts (plain JavaScript, no modules). The first runs before three.js and
// records errors: uncaught exceptions, rejected promises and console.error calls set
// <html data-status="error"> and are listed in #errors. The second is the viewer: it reads the
// .glb scenes from the page's <script type="application/octet-stream" class="scene"> elements
// (base64), draws them with three.js (THREE.GLTFLoader, THREE.OrbitControls) into #viewer and
// plays their first animation.
const char* report_error_script();
const char* report_viewer_script();

}  // namespace hila::viz
