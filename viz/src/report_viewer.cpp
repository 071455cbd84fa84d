#include "report_viewer.hpp"

namespace hila::viz {

const char* report_error_script() {
  return R"JS(
(function () {
  'use strict';
  var root = document.documentElement;
  var errors = [];
  root.dataset.status = 'loading';
  function fail(message) {
    errors.push(String(message));
    root.dataset.status = 'error';
    var list = document.getElementById('errors');
    if (list) {
      list.textContent = errors.join('\n');
      list.hidden = false;
    }
  }
  window.hilaFail = fail;
  window.hilaErrors = errors;
  var consoleError = console.error;
  console.error = function () {
    consoleError.apply(console, arguments);
    fail(Array.prototype.map.call(arguments, String).join(' '));
  };
  window.addEventListener('error', function (e) {
    fail((e.message || 'error') + (e.filename ? ' (' + e.filename + ':' + e.lineno + ')' : ''));
  });
  window.addEventListener('unhandledrejection', function (e) {
    fail('unhandled promise rejection: ' + (e.reason && e.reason.message || e.reason));
  });
})();
)JS";
}

const char* report_viewer_script() {
  return R"JS(
(function () {
  'use strict';
  var root = document.documentElement;
  // The URL's hash: t=SECONDS shows the animation paused there; scene=N opens scene N;
  // clip=NAME plays the animation of that name (a board's own).
  var hash = {};
  location.hash.replace(/^#/, '').split('&').forEach(function (kv) {
    var p = kv.split('=');
    if (p[0]) hash[decodeURIComponent(p[0])] = decodeURIComponent(p[1] || '');
  });
  var fixedTime = hash.t !== undefined ? Number(hash.t) : null;
  if (fixedTime !== null && !isFinite(fixedTime)) {
    hilaFail('#t=' + hash.t + ': not a number of seconds');
    fixedTime = null;
  }

  var background = new THREE.Color(0xeef1f4);
  var container = document.getElementById('viewer');
  var canvas = document.createElement('canvas');
  container.appendChild(canvas);
  var renderer = new THREE.WebGLRenderer({canvas: canvas, antialias: true,
                                          preserveDrawingBuffer: true});
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  if ('outputEncoding' in renderer) renderer.outputEncoding = THREE.sRGBEncoding;
  else renderer.gammaOutput = true;  // three.js before r112: glTF colours are linear
  var camera = new THREE.PerspectiveCamera(35, 1, 0.02, 50);
  camera.up.set(0, 0, 1);  // hila's world: z up
  var controls = new THREE.OrbitControls(camera, canvas);
  controls.enableDamping = false;
  var scene = null;
  var mixer = null;
  var duration = 0;
  var playing = fixedTime === null;
  var clock = new THREE.Clock();

  var sceneMenu = document.getElementById('scene');
  var clipMenu = document.getElementById('clip');
  var clips = [];
  var playButton = document.getElementById('play');
  var slider = document.getElementById('time');
  var timeText = document.getElementById('time-text');
  var speedMenu = document.getElementById('speed');
  var sources = document.querySelectorAll('script.scene');

  function resize() {
    var w = container.clientWidth, h = container.clientHeight;
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  }

  function decode(text) {
    var bin = atob(text.replace(/\s+/g, ''));
    var bytes = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
    return bytes.buffer;
  }

  // The fraction of sampled pixels that differ from the most frequent colour (the background):
  // 0 for a blank canvas.
  function filledFraction() {
    var gl = renderer.getContext();
    var w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    var pixels = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    var counts = {}, samples = [];
    for (var i = 0; i < pixels.length; i += 4 * 7) {
      var key = (pixels[i] >> 3) + ',' + (pixels[i + 1] >> 3) + ',' + (pixels[i + 2] >> 3);
      counts[key] = (counts[key] || 0) + 1;
      samples.push(key);
    }
    var most = 0;
    for (var k in counts) most = Math.max(most, counts[k]);
    return samples.length ? 1 - most / samples.length : 0;
  }

  function showTime(t) {
    slider.value = t;
    timeText.textContent = t.toFixed(2) + ' / ' + duration.toFixed(2) + ' s';
  }

  function frame() {
    if (!scene) return;
    var dt = clock.getDelta();
    if (mixer && playing) {
      mixer.update(dt * Number(speedMenu.value));
      showTime(mixer.time % Math.max(duration, 1e-9));
    }
    controls.update();
    renderer.render(scene, camera);
  }

  function frameView(object) {
    var box = new THREE.Box3().setFromObject(object);
    var centre = box.getCenter(new THREE.Vector3());
    var size = box.getSize(new THREE.Vector3()).length();
    // From the front left, above the table, looking at the middle of the cell.
    camera.position.copy(centre).add(new THREE.Vector3(-0.55, -0.75, 0.45).multiplyScalar(size));
    camera.near = size / 200;
    camera.far = size * 10;
    camera.updateProjectionMatrix();
    controls.target.copy(centre);
    controls.update();
  }

  function playClip(index, time) {
    var clip = clips[index];
    mixer.stopAllAction();
    duration = clip.duration;
    mixer.clipAction(clip).play();
    mixer.setTime(Math.min(time, duration));
    slider.max = duration;
  }

  function open(index) {
    var source = sources[index];
    if (!source) {
      hilaFail('no scene ' + index + ' in the page');
      return;
    }
    root.dataset.status = 'loading';
    var loader = new THREE.GLTFLoader();
    loader.parse(decode(source.textContent), '', function (gltf) {
      scene = new THREE.Scene();
      scene.background = background;
      var sky = new THREE.HemisphereLight(0xffffff, 0x707070, 0.85);
      sky.position.set(0, 0, 1);
      scene.add(sky);
      var sun = new THREE.DirectionalLight(0xffffff, 0.75);
      sun.position.set(1.5, -2.5, 4);
      scene.add(sun);
      scene.add(gltf.scene);
      frameView(gltf.scene);
      mixer = null;
      duration = 0;
      // The animations: the first ("plan": the whole plan) plays; the menu picks another (a
      // board's own).
      clips = gltf.animations;
      clipMenu.textContent = '';
      clips.forEach(function (c, i) {
        var option = document.createElement('option');
        option.value = i;
        option.textContent = c.name || ('animation ' + i);
        clipMenu.appendChild(option);
      });
      clipMenu.hidden = clips.length < 2;
      if (clips.length > 0) {
        // #clip=NAME: that animation (a board's), else the first.
        var first = Math.max(0, clips.findIndex(function (c) { return c.name === hash.clip; }));
        clipMenu.value = first;
        mixer = new THREE.AnimationMixer(gltf.scene);
        playClip(first, fixedTime !== null ? fixedTime : 0);
      }
      slider.max = duration;
      slider.disabled = playButton.disabled = !mixer;
      playButton.textContent = playing ? 'pause' : 'play';
      showTime(mixer ? mixer.time : 0);
      clock.getDelta();
      frame();
      root.dataset.canvasFilled = filledFraction().toFixed(4);
      if (root.dataset.status !== 'error') root.dataset.status = 'ready';
    }, function (error) {
      hilaFail('cannot read scene ' + index + ': ' + (error && error.message || error));
    });
  }

  sources.forEach(function (s, i) {
    var option = document.createElement('option');
    option.value = i;
    option.textContent = s.dataset.title;
    sceneMenu.appendChild(option);
  });
  sceneMenu.addEventListener('change', function () { open(Number(sceneMenu.value)); });
  clipMenu.addEventListener('change', function () {
    if (!mixer) return;
    playClip(Number(clipMenu.value), 0);
    showTime(0);
  });
  playButton.addEventListener('click', function () {
    playing = !playing;
    playButton.textContent = playing ? 'pause' : 'play';
    clock.getDelta();
  });
  slider.addEventListener('input', function () {
    if (!mixer) return;
    playing = false;
    playButton.textContent = 'play';
    mixer.setTime(Number(slider.value));
    showTime(Number(slider.value));
  });
  window.addEventListener('resize', resize);
  resize();
  var first = hash.scene !== undefined ? Number(hash.scene) : sources.length - 1;
  sceneMenu.value = first;
  open(first);
  renderer.setAnimationLoop(frame);
})();
)JS";
}

}  // namespace hila::viz
