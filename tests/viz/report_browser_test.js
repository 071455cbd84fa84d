#!/usr/bin/env node
// The report page in a real browser: builds a small cabinet database, plans every board, writes
// report.html with `hila report html`, and loads it from the file system in headless Chromium
// (software WebGL). Checks: the page is at most 20 MB and loads nothing from the network; it
// reaches data-status "ready" with no error logged (uncaught exceptions, console.error, the
// GLTFLoader's); its canvas is not blank (the page's own pixel count and the screenshot's); the
// screenshots at two animation times (#t=SECONDS) differ in the viewer; the animation menu lists
// "plan" and the boards' own; the first grasps and goals scenes (#scene=N) are drawn.
// Usage: report_browser_test.js HILA_EXE SOURCE_DIR [--report report.html (skips the build)]
// Exits 77 (ctest SKIP_RETURN_CODE) when no Chromium is installed.
'use strict';
const {execFileSync, execFile} = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');
const zlib = require('zlib');

const [hila, source] = process.argv.slice(2, 4);
const reportArg = process.argv.indexOf('--report');
const fail = (message) => {
  console.error('FAIL: ' + message);
  process.exit(1);
};

const chromium = ['chromium', 'chromium-browser', 'google-chrome'].find((name) => {
  try {
    execFileSync('sh', ['-c', 'command -v ' + name], {stdio: 'ignore'});
    return true;
  } catch (e) {
    return false;
  }
});
if (!chromium) {
  console.log('SKIP: no chromium on PATH (tools/setup installs Debian\'s chromium)');
  process.exit(77);
}

const work = fs.mkdtempSync(path.join(os.tmpdir(), 'hila-report-'));
// Runs hila; exit 1 (a board without a goal or a plan) still writes `output`.
const run = (args, output) => {
  try {
    execFileSync(hila, args, {cwd: source, stdio: ['ignore', 'pipe', 'pipe']});
  } catch (e) {
    if (e.status !== 1 || !fs.existsSync(output)) {
      fail('hila ' + args.join(' ') + ': ' + e.message + '\n' + e.stderr);
    }
  }
};
let report = path.join(work, 'report.html');
if (reportArg > 0) {
  report = path.resolve(process.argv[reportArg + 1]);
} else {
  const db = path.join(work, 'cabinet.hila');
  const plan = path.join(work, 'plan.json');
  // A quick database (about 15 s on two cores) in which most boards have a goal.
  run(['build', 'meshes/cabinet/product.yaml', '--cell', 'meshes/cell/cell.yaml', '-o', db,
       '--comfort-samples', '200000', '--handover-candidates', '20', '--roadmap-nodes', '100',
       '--jobs', '2'], db);
  run(['plan', '--db', db, '--scene', 'meshes/cabinet/scene.yaml', '--all', '-o', plan], plan);
  run(['report', 'html', db, '--plan', plan, '-o', report], report);
}

const html = fs.readFileSync(report, 'utf8');
console.log('report.html: ' + html.length + ' bytes');
if (html.length > 20e6) fail('report.html is ' + html.length + ' bytes, over 20 MB');
const external = html.match(/<(script|link|img|iframe)\b[^>]*\b(src|href)\s*=/i);
if (external) fail('the page loads a file: ' + external[0]);
if (!html.includes('GLTFLoader') || !html.includes('class="scene"')) fail('no viewer in the page');

const window = {width: 1100, height: 760};
const chromiumArgs = ['--headless', '--no-sandbox', '--use-angle=swiftshader',
                      '--enable-unsafe-swiftshader', '--hide-scrollbars', '--mute-audio',
                      '--no-first-run', '--disable-extensions', '--enable-logging=stderr', '--v=0',
                      `--window-size=${window.width},${window.height}`,
                      '--virtual-time-budget=5000'];
const url = (time) => 'file://' + report + '#t=' + time;
const browse = (args) => new Promise((resolve) => {
  execFile(chromium, chromiumArgs.concat(args), {maxBuffer: 64 << 20, timeout: 60000},
           (error, stdout, stderr) => resolve({error, stdout, stderr}));
});

// The console's errors as Chromium logs them (the page also catches them itself).
function consoleErrors(stderr) {
  return stderr.split('\n').filter((l) => /CONSOLE/.test(l) && /error|Uncaught/i.test(l));
}

// Decodes an 8-bit RGB or RGBA PNG (what Chromium writes) into {width, height, rgba}.
function readPng(file) {
  const data = fs.readFileSync(file);
  let offset = 8, width = 0, height = 0, type = 0;
  const idat = [];
  while (offset < data.length) {
    const length = data.readUInt32BE(offset);
    const kind = data.toString('ascii', offset + 4, offset + 8);
    const body = data.subarray(offset + 8, offset + 8 + length);
    if (kind === 'IHDR') {
      width = body.readUInt32BE(0);
      height = body.readUInt32BE(4);
      if (body[8] !== 8 || body[12] !== 0) fail(file + ': not an 8-bit non-interlaced PNG');
      type = body[9];
    } else if (kind === 'IDAT') {
      idat.push(body);
    }
    offset += 12 + length;
  }
  const channels = type === 6 ? 4 : type === 2 ? 3 : fail(file + ': PNG colour type ' + type);
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const out = Buffer.alloc(width * height * 4);
  let previous = Buffer.alloc(stride);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)];
    const line = Buffer.from(raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1)));
    for (let i = 0; i < stride; ++i) {
      const a = i >= channels ? line[i - channels] : 0;
      const b = previous[i];
      const c = i >= channels ? previous[i - channels] : 0;
      let add = 0;
      if (filter === 1) add = a;
      else if (filter === 2) add = b;
      else if (filter === 3) add = (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
        add = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      line[i] = (line[i] + add) & 255;
    }
    for (let x = 0; x < width; ++x) {
      for (let k = 0; k < 3; ++k) out[(y * width + x) * 4 + k] = line[x * channels + k];
      out[(y * width + x) * 4 + 3] = 255;
    }
    previous = line;
  }
  return {width, height, rgba: out};
}

// The viewer's area in the screenshot: below the title, above the controls (CSS pixels).
const viewer = {x0: 24, x1: 1076, y0: 90, y1: 620};

function viewerStats(png, other) {
  const colours = new Map();
  let differ = 0, pixels = 0;
  for (let y = viewer.y0; y < viewer.y1; y += 2) {
    for (let x = viewer.x0; x < viewer.x1; x += 2) {
      const i = (y * png.width + x) * 4;
      const key = png.rgba.readUInt32BE(i);
      colours.set(key, (colours.get(key) || 0) + 1);
      ++pixels;
      if (other && other.rgba.readUInt32BE(i) !== key) ++differ;
    }
  }
  const background = Math.max(...colours.values());
  return {colours: colours.size, filled: 1 - background / pixels, differ: differ / pixels};
}

(async () => {
  const times = [5, 40];
  const shots = times.map((t) => path.join(work, `t${t}.png`));
  const [dom, ...screens] = await Promise.all([
    browse(['--dump-dom', url(times[0])]),
    ...times.map((t, k) => browse(['--screenshot=' + shots[k], url(t)])),
  ]);
  for (const r of [dom, ...screens]) {
    if (r.error) fail('chromium: ' + r.error.message + '\n' + r.stderr.slice(-2000));
    const logged = consoleErrors(r.stderr);
    if (logged.length) fail('the page logged errors:\n' + logged.join('\n'));
  }
  const status = /<html[^>]*\bdata-status="([^"]*)"/.exec(dom.stdout);
  const errors = /<pre id="errors"[^>]*>([^<]*)</.exec(dom.stdout);
  if (errors && errors[1].trim()) fail('the page reports errors: ' + errors[1]);
  if (!status || status[1] !== 'ready') fail('page status ' + (status ? status[1] : 'missing'));
  const canvasFilled = Number((/data-canvas-filled="([^"]*)"/.exec(dom.stdout) || [])[1]);
  console.log('canvas: ' + (100 * canvasFilled).toFixed(1) + ' % of its pixels drawn');
  if (!(canvasFilled > 0.05)) fail('the canvas is blank (' + canvasFilled + ' drawn)');

  const [a, b] = shots.map(readPng);
  const sa = viewerStats(a), sb = viewerStats(b, a);
  console.log(`screenshots: ${sa.colours} and ${sb.colours} colours in the viewer, ` +
              `${(100 * sa.filled).toFixed(1)} % and ${(100 * sb.filled).toFixed(1)} % drawn, ` +
              `${(100 * sb.differ).toFixed(2)} % of pixels differ between t=${times[0]} and ` +
              `t=${times[1]} s`);
  for (const s of [sa, sb]) {
    if (s.colours < 50 || s.filled < 0.05) fail('a screenshot\'s viewer is blank');
  }
  if (sb.differ < 0.002) fail('the screenshots at the two times do not differ');

  // The plan's animations in the menu: the whole plan first, then each planned board's own.
  const clipMenu = /<select id="clip"[^>]*>(.*?)<\/select>/.exec(dom.stdout);
  const clipNames = clipMenu ? [...clipMenu[1].matchAll(/<option[^>]*>([^<]*)</g)].map((m) => m[1])
                             : [];
  console.log('animations: ' + clipNames.join(', '));
  if (clipNames[0] !== 'plan' || clipNames.length < 2) fail('no per-board animations in the menu');

  // The first grasps and goals scenes load and draw.
  const titles = [...html.matchAll(/<script type="application\/octet-stream" class="scene" data-title="([^"]*)"/g)]
                     .map((m) => m[1]);
  for (const kind of ['grasps: ', 'goals: ']) {
    const index = titles.findIndex((t) => t.startsWith(kind));
    if (index < 0) fail('no ' + kind + 'scene in the page');
    const r = await browse(['--dump-dom', 'file://' + report + '#scene=' + index]);
    if (r.error) fail('chromium: ' + r.error.message + '\n' + r.stderr.slice(-2000));
    const logged = consoleErrors(r.stderr);
    if (logged.length) fail(titles[index] + ': the page logged errors:\n' + logged.join('\n'));
    const sceneStatus = /<html[^>]*\bdata-status="([^"]*)"/.exec(r.stdout);
    const filled = Number((/data-canvas-filled="([^"]*)"/.exec(r.stdout) || [])[1]);
    console.log(titles[index] + ': ' + (sceneStatus ? sceneStatus[1] : 'no status') + ', ' +
                (100 * filled).toFixed(1) + ' % drawn');
    if (!sceneStatus || sceneStatus[1] !== 'ready') fail(titles[index] + ': not ready');
    if (!(filled > 0.02)) fail(titles[index] + ': the canvas is blank');
  }
  if (reportArg < 0) fs.rmSync(work, {recursive: true, force: true});
  console.log('PASS');
})();
