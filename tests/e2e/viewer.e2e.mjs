// End-to-end test of the browser viewer (ctest: e2e.viewer): starts `lacuna serve` on a generated
// volume on a free port, loads the page in Debian's headless chromium through playwright-core,
// waits for a frame, drags a TF opacity point, and checks that the image changes, that the
// overlay reports the TF-change time, that a second tab is served, that the page logged no
// console errors, and that Ctrl-C (SIGINT) stops the server cleanly. Then patient orientation
// (issue 14): on a phantom stored LPS, the page's view menu and its clip-plane box give the frames
// `lacuna render --view ... --clip ...` gives, byte for byte (the frame's JPEG against the CLI's
// PNG through the server's own encoder, --jpeg). Saving work: the TF downloaded as lacuna JSON and
// exported as Slicer .vp.json (both rendered by `lacuna render --tf`) and uploaded back into the
// editor; the screenshot button's PNG equals `lacuna render --session` of the saved session, byte
// for byte. A 4D NIfTI file: the frame selector switches the server's volume (the frame and the
// saved session follow). Saves a screenshot of the viewer to --screenshot
// (default docs/images/viewer.png, the README picture; ctest passes a path in the build folder so
// a test run leaves the checkout untouched).
//
// Usage: node tests/e2e/viewer.e2e.mjs [--lacuna build/lacuna] [--chromium /usr/bin/chromium]
//                                       [--jpeg build/lacuna_e2e_jpeg]
//                                       [--screenshot docs/images/viewer.png]
import { spawn, execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';

const args = { lacuna: 'build/lacuna', chromium: '/usr/bin/chromium', jpeg: 'build/lacuna_e2e_jpeg',
               screenshot: 'docs/images/viewer.png' };
for (let i = 2; i + 1 < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];

const dir = mkdtempSync(join(tmpdir(), 'lacuna-e2e-'));
let server = null;
let server2 = null;  // the orientation part's server (the LPS phantom)
let browser = null;
const watchdog = setTimeout(() => fail("timed out after 270 s"), 270_000);

function fail(message) {
  console.error(`e2e.viewer: FAIL: ${message}`);
  if (server) server.kill('SIGKILL');
  if (server2) server2.kill('SIGKILL');
  if (browser) browser.close().catch(() => {});
  rmSync(dir, { recursive: true, force: true });
  process.exit(1);
}
function check(cond, message) { if (!cond) fail(message); else console.log(`ok - ${message}`); }
const fmt = (x) => String(+x.toPrecision(4));

// The server prints its URL once it listens ("lacuna viewer: http://127.0.0.1:PORT/ ...").
function spawnServer(volume, tf, onStarted, extra = []) {
  return new Promise((resolve, reject) => {
    const s = spawn(args.lacuna, ['serve', volume, '--port', '0', '--tf', tf, ...extra],
                    { stdio: ['ignore', 'pipe', 'pipe'] });
    onStarted(s);
    let out = '';
    s.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/lacuna viewer: (http:\/\/127\.0\.0\.1:\d+\/)/);
      if (m) resolve(m[1]);
    });
    s.stderr.on('data', (d) => process.stderr.write(d));
    s.on('exit', (code) => reject(new Error(`lacuna serve exited with ${code}: ${out}`)));
  });
}
const startServer = (volume) => spawnServer(volume, 'mr-default', (s) => { server = s; });

// An asymmetric head phantom stored LPS (tests/render/orientation_test_util.h's, in a NRRD
// written here): voxel i runs toward the patient's left, j posterior, k superior; in world
// (RAS mm, centred on 0) a faint body (50), a marker on the patient's right (220), one in front
// (160), one on top (100). Mirrored or permuted handling shows as another picture.
// With `labels`, the phantom's label map instead (same grid): 1 the right marker (> 200), 2 the
// front one (> 140), 3 the top one (> 80), 0 elsewhere.
function writeLpsPhantom(path, labels = false) {
  const [nx, ny, nz] = [41, 49, 37], sp = [1, 1.25, 1.5];
  // LPS position of voxel (0,0,0), RAS (20, 30, -27): the right-anterior-inferior corner.
  const origin = [-20, -30, -27];
  const bump = (d, r, v) => v * Math.min(1, Math.max(0, (r - d) / 2.5));
  const data = Buffer.alloc(nx * ny * nz);
  for (let k = 0; k < nz; k++) for (let j = 0; j < ny; j++) for (let i = 0; i < nx; i++) {
    // LPS (origin + index * spacing) -> RAS: x and y negated.
    const x = -(origin[0] + i * sp[0]), y = -(origin[1] + j * sp[1]), z = origin[2] + k * sp[2];
    const body = Math.sqrt(x * x / 256 + y * y / 484 + z * z / 400);
    let v = 50 * Math.min(1, Math.max(0, (1 - body) * 5));
    v = Math.max(v, bump(Math.hypot(x - 11, y + 2, z), 5, 220));
    v = Math.max(v, bump(Math.hypot(x, y - 17, z + 4), 4.5, 160));
    v = Math.max(v, bump(Math.hypot(x + 3, y + 4, z - 16), 4.5, 100));
    v = Math.round(v);
    data[(k * ny + j) * nx + i] = labels ? (v > 200 ? 1 : v > 140 ? 2 : v > 80 ? 3 : 0) : v;
  }
  const header = 'NRRD0004\ntype: uint8\ndimension: 3\nspace: left-posterior-superior\n' +
    `sizes: ${nx} ${ny} ${nz}\nspace directions: (${sp[0]},0,0) (0,${sp[1]},0) (0,0,${sp[2]})\n` +
    'kinds: domain domain domain\nencoding: raw\n' +
    `space origin: (${origin[0]},${origin[1]},${origin[2]})\n\n`;
  writeFileSync(path, Buffer.concat([Buffer.from(header, 'ascii'), data]));
}
// A NIfTI-1 file of `frames` uint8 volumes along dim[4] (no qform/sform: pixdim only): in volume
// f a bright ball of radius 3 + 3f in a faint box, so each volume renders differently.
function write4dNifti(path, [nx, ny, nz], frames) {
  const hdr = Buffer.alloc(352);
  hdr.writeInt32LE(348, 0);
  [4, nx, ny, nz, frames, 1, 1, 1].forEach((d, i) => hdr.writeInt16LE(d, 40 + 2 * i));
  hdr.writeInt16LE(2, 70);  // datatype uint8
  hdr.writeInt16LE(8, 72);  // bitpix
  for (let i = 0; i < 8; i++) hdr.writeFloatLE(1, 76 + 4 * i);
  hdr.writeFloatLE(352, 108);  // vox_offset
  hdr.write('n+1\0', 344, 'latin1');
  const data = Buffer.alloc(nx * ny * nz * frames);
  for (let f = 0; f < frames; f++) for (let k = 0; k < nz; k++) for (let j = 0; j < ny; j++) for (let i = 0; i < nx; i++) {
    const r = Math.hypot(i - nx / 2, j - ny / 2, k - nz / 2);
    data[((f * nz + k) * ny + j) * nx + i] = r < 3 + 3 * f ? 220 : 30;
  }
  writeFileSync(path, Buffer.concat([hdr, data]));
}

// A faint grey body and, opaque, only the right marker (220) in red: where the patient's right is
// shows in the picture.
const kPhantomTf = {
  name: 'right-marker', domain: 'value',
  color: [[0, 0.5, 0.5, 0.5], [60, 0.5, 0.5, 0.5], [190, 1.0, 0.1, 0.1], [255, 1.0, 0.1, 0.1]],
  opacity: [[0, 0], [35, 0], [45, 0.03], [60, 0.03], [70, 0], [190, 0], [200, 0.9], [255, 0.9]],
};

// A binary frame: u32 LE header length, the JSON header, the JPEG (docs/viewer.md, Protocol).
function parseFrame(buf) {
  const n = buf.readUInt32LE(0);
  return { header: JSON.parse(buf.subarray(4, 4 + n).toString('utf8')), jpeg: buf.subarray(4 + n) };
}

// Waits for a full-resolution frame newer than `after` frames.
async function waitFullFrame(page, after) {
  await page.waitForFunction((n) => window.lacunaViewer.frames() > n &&
      !document.getElementById('o-frame').textContent.includes('preview'), after, { timeout: 30_000 });
  // Let a full frame requested at the end of a drag arrive too.
  await page.waitForTimeout(400);
  await page.waitForFunction(() => !document.getElementById('o-frame').textContent.includes('preview'),
                             null, { timeout: 30_000 });
}

try {
  const volume = join(dir, 'tree.nrrd');
  execFileSync(args.lacuna, ['generate', 'tree', '--dims', '96x96x96', '--out', volume], { stdio: 'ignore' });
  const url = await startServer(volume);
  console.log(`server at ${url}`);

  browser = await chromium.launch({ executablePath: args.chromium, headless: true,
                                    args: ['--no-sandbox', '--disable-gpu'] });
  const context = await browser.newContext({ viewport: { width: 1100, height: 680 } });
  const page = await context.newPage();
  const consoleErrors = [];
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => consoleErrors.push(String(e)));

  // The page's slice messages, as they went over its WebSocket.
  const slicesSent = [];
  page.on('websocket', (ws) => ws.on('framesent', (f) => {
    if (typeof f.payload !== 'string') return;
    const m = JSON.parse(f.payload);
    if (m.type === 'slice') slicesSent.push(m);
  }));
  await page.goto(url);
  await waitFullFrame(page, 0);
  check(true, 'the page shows a frame');
  const accels = await page.$$eval('#accel option', (os) => os.map((o) => o.value));
  check(accels.includes('bitfield') && accels.includes('none'), `accel selector lists ${accels.join(', ')}`);

  // Slice panes (issue 18 item 1): the three planes come from the server through `slice`
  // messages; a click in one moves the crosshair there, the other two are fetched through the new
  // point and the probe readout follows; window/level (shift-drag, the preset menu) changes the
  // pictures. Without --labels the segments and overlay rows stay hidden.
  {
    const planes = ['axial', 'coronal', 'sagittal'];
    const slices = () => page.evaluate(() => window.lacunaViewer.slices());
    const settled = () => page.waitForFunction(() => {
      const s = window.lacunaViewer.slices();
      return ['axial', 'coronal', 'sagittal'].every((p) => s[p].count > 0 && s[p].settled);
    }, null, { timeout: 30_000 });
    const paneShot = (plane) => page.locator(`#pane-${plane} canvas`).screenshot();
    await settled();
    let sl = await slices();
    check(planes.every((p) => sl[p].header.plane === p && sl[p].header.width > 1 && sl[p].header.height > 1),
          `the three slice panes show slices (${planes.map((p) => `${sl[p].header.width}x${sl[p].header.height}`).join(', ')})`);
    check(planes.every((p) => slicesSent.some((m) => m.plane === p)), 'the panes ask with slice messages');
    const display = await page.evaluate(() => ['segments-row', 'overlay-row'].map(
        (id) => getComputedStyle(document.getElementById(id)).display));
    check(display.every((d) => d === 'none'), `without --labels the segments and overlay rows are hidden (${display})`);
    await page.waitForFunction(() => window.lacunaViewer.probe() !== null, null, { timeout: 30_000 });
    const readout0 = await page.textContent('#probe');

    // Click at a pixel off the crosshair in the axial pane.
    const ax = sl.axial.header;
    const c = Math.round(ax.width * 0.3), r = Math.round(ax.height * 0.65);
    const want = [0, 1, 2].map((a) => ax.origin[a] + c * ax.u[a] + r * ax.v[a]);
    const before = await page.evaluate(() => window.lacunaViewer.state.point);
    const at = await page.evaluate(([c, r]) => window.lacunaViewer.sliceClient('axial', c, r), [c, r]);
    await page.mouse.click(at.x, at.y);
    const point = await page.evaluate(() => window.lacunaViewer.state.point);
    // The mouse lands within half a CSS pixel of the pixel's centre: less than a slice pixel here.
    const off = Math.hypot(point[0] - want[0], point[1] - want[1]);
    check(off <= ax.pixel_mm && Math.abs(point[2] - before[2]) < 1e-9,
          `the click moves the crosshair to the clicked pixel (${point.map((x) => x.toFixed(2))}, ${off.toFixed(3)} mm off; z kept)`);
    await settled();
    sl = await slices();
    check(['coronal', 'sagittal'].every((p) => JSON.stringify(sl[p].point) === JSON.stringify(point)),
          'the coronal and sagittal panes are fetched through the new point');
    check(Math.abs(sl.coronal.header.origin[1] - point[1]) < 1e-6 && Math.abs(sl.sagittal.header.origin[0] - point[0]) < 1e-6,
          `their planes pass through it (coronal y ${sl.coronal.header.origin[1]}, sagittal x ${sl.sagittal.header.origin[0]})`);
    // The crosshair is drawn at the click in the axial pane, in its colour.
    const cross = await page.evaluate(() => {
      const cv = document.querySelector('#pane-axial canvas');
      const [x, y] = window.lacunaViewer.crosshairCanvas('axial');
      const f = window.lacunaViewer.slices().axial.fit;
      const px = cv.getContext('2d').getImageData(x, f.oy + 2, 1, 1).data;
      return { x, y, rgb: [px[0], px[1], px[2]] };
    });
    const rect = await page.locator('#pane-axial canvas').boundingBox();
    const cw = await page.evaluate(() => document.querySelector('#pane-axial canvas').width);
    const k = cw / rect.width;
    check(Math.abs(cross.x - (at.x - rect.x) * k) <= 1.5 && Math.abs(cross.y - (at.y - rect.y) * k) <= 1.5 &&
          cross.rgb.join() === '255,204,0', `the axial crosshair is drawn at the click (${cross.x}, ${cross.y}: ${cross.rgb})`);
    await page.waitForFunction((p) => {
      const pr = window.lacunaViewer.probe();
      return pr && JSON.stringify(pr.point) === JSON.stringify(p);
    }, point, { timeout: 30_000 });
    const probe = await page.evaluate(() => window.lacunaViewer.probe());
    const readout = await page.textContent('#probe');
    check(readout !== readout0 && probe.inside && readout.includes(`voxel [${probe.voxel.join(', ')}]`) &&
          readout.includes(point[0].toFixed(1)) &&
          probe.voxel.every((v, a) => v === Math.floor(probe.index[a] + 0.5)),
          `the probe readout follows: "${readout.replace(/\n/g, ' | ')}"`);

    // Shift-drag in the axial pane (the tree's central plane: 2% of it is the tree, the rest
    // 0 and black under any window): window and level change, the picture too, the point stays.
    const ax0 = await paneShot('axial');
    const wl0 = await page.evaluate(() => [window.lacunaViewer.state.window, window.lacunaViewer.state.level]);
    const box = await page.locator('#pane-axial').boundingBox();
    await page.keyboard.down('Shift');
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width / 2 - 60, box.y + box.height / 2 + 40, { steps: 6 });
    await page.mouse.up();
    await page.keyboard.up('Shift');
    const st = await page.evaluate(() => window.lacunaViewer.state);
    check(st.window < wl0[0] && st.level > wl0[1] && st.wlPreset === 'custom' &&
          JSON.stringify(st.point) === JSON.stringify(point),
          `shift-drag sets window/level (${wl0.map(fmt).join('/')} -> ${fmt(st.window)}/${fmt(st.level)}), the crosshair stays`);
    await settled();
    const ax1 = await paneShot('axial');
    check(Buffer.compare(ax0, ax1) !== 0, 'window/level changes the slice');
    await page.selectOption('#wl-preset', 'full');
    const full = await page.evaluate(() => [window.lacunaViewer.state.window, window.lacunaViewer.hello().volume.data_range]);
    check(Math.abs(full[0] - (full[1][1] - full[1][0])) < 1e-9, `the full-range preset sets the window to the data range (${fmt(full[0])})`);
    await settled();
    check(Buffer.compare(ax1, await paneShot('axial')) !== 0, 'and changes the slice again');
  }

  // Drag the second opacity point of mr-default ((0.1, 0): where the ramp starts) upward.
  const img = page.locator('#frame');
  const before = await img.screenshot();
  const p = await page.evaluate(() => window.lacunaViewer.opacityPointClient(1));
  const framesBefore = await page.evaluate(() => window.lacunaViewer.frames());
  await page.mouse.move(p.x, p.y);
  await page.mouse.down();
  await page.mouse.move(p.x + 30, p.y - 40, { steps: 8 });
  await page.mouse.move(p.x + 40, p.y - 90, { steps: 8 });
  await page.mouse.up();
  await waitFullFrame(page, framesBefore);
  const after = await img.screenshot();
  check(Buffer.compare(before, after) !== 0, 'dragging a TF point changes the image');
  const opacity = await page.evaluate(() => window.lacunaViewer.state.tf.opacity[1][1]);
  check(opacity > 0.3, `the point moved up (opacity ${opacity})`);
  const tfText = await page.textContent('#o-tf');
  const tfMs = Number(await page.getAttribute('#o-tf', 'data-ms'));
  check(/ms update/.test(tfText) && Number.isFinite(tfMs) && tfMs >= 0,
        `overlay reports the TF change: "${tfText}"`);

  // The shading and clip-plane toggles each change the picture.
  for (const id of ['shading', 'clip']) {
    const shot = await img.screenshot();
    const n = await page.evaluate(() => window.lacunaViewer.frames());
    await page.check('#' + id);
    await waitFullFrame(page, n);
    check(Buffer.compare(shot, await img.screenshot()) !== 0, `the ${id} toggle changes the image`);
  }

  // The slice renderer (the page switches the structure to kdtree and the toggles off).
  {
    const n = await page.evaluate(() => window.lacunaViewer.frames());
    await page.selectOption('#renderer', 'slice');
    await waitFullFrame(page, n);
    const st = await page.evaluate(() => window.lacunaViewer.state);
    check(st.renderer === 'slice' && st.accel === 'kdtree' && !st.shading,
          `the slicer renders (structure ${st.accel})`);
    // The page follows the server's capabilities table: a structure the slicer does not take
    // moves the page to a renderer that does.
    const caps = await page.evaluate(() => window.lacunaViewer.hello().capabilities);
    check(caps && caps.slice.accels.join() === 'none,kdtree' && caps.march.accels.includes('bitfield'),
          `the hello message carries the capabilities (slicer: ${caps && caps.slice.accels.join(', ')})`);
    const m = await page.evaluate(() => window.lacunaViewer.frames());
    await page.selectOption('#accel', 'bitfield');
    await waitFullFrame(page, m);
    const st2 = await page.evaluate(() => window.lacunaViewer.state);
    check(st2.renderer === 'march' && st2.accel === 'bitfield',
          `a structure the slicer lacks switches to the marcher (${st2.renderer}, ${st2.accel})`);
  }

  // Saving work (issue 18 item 2): the TF as lacuna JSON and as Slicer .vp.json, both read by
  // `lacuna render --tf`, uploaded back into the editor; a screenshot rendered by the server and a
  // saved session that `lacuna render --session` renders to the screenshot's bytes.
  {
    const saved = async (button, name) => {
      const [dl] = await Promise.all([page.waitForEvent('download', { timeout: 60_000 }), page.click(button)]);
      const path = join(dir, name);
      await dl.saveAs(path);
      return { path, suggested: dl.suggestedFilename() };
    };
    const cliRender = (flags) => {
      try {
        execFileSync(args.lacuna, ['render', ...flags], { stdio: 'pipe' });
        return 0;
      } catch (e) {
        console.error(String(e.stderr || e));
        return e.status ?? 1;
      }
    };
    const edited = await page.evaluate(() => JSON.parse(JSON.stringify(window.lacunaViewer.state.tf)));
    const tfJson = await saved('#tf-download', 'downloaded-tf.json');
    const tfFile = JSON.parse(readFileSync(tfJson.path, 'utf8'));
    check(tfJson.suggested.endsWith('.json') && JSON.stringify(tfFile.opacity) === JSON.stringify(edited.opacity) &&
          JSON.stringify(tfFile.color) === JSON.stringify(edited.color) && tfFile.domain === edited.domain,
          `the TF download is the editor's TF as lacuna JSON (${tfJson.suggested}, ${tfFile.opacity.length} opacity points)`);
    check(cliRender([volume, '--tf', tfJson.path, '--size', '48', '--out', join(dir, 'tf-json.png')]) === 0,
          'lacuna render --tf reads the downloaded TF');
    const vp = await saved('#tf-slicer', 'exported.vp.json');
    const vpDoc = JSON.parse(readFileSync(vp.path, 'utf8'));
    const comp = vpDoc.volumeProperties[0].components[0];
    check(vp.suggested.endsWith('.vp.json') && comp.scalarOpacity.points.length === edited.opacity.length &&
          comp.rgbTransferFunction.points.length === edited.color.length,
          `the Slicer export is a .vp.json with the TF's points (${vp.suggested})`);
    check(cliRender([volume, '--tf', vp.path, '--size', '48', '--out', join(dir, 'tf-vp.png')]) === 0,
          'lacuna render --tf reads the exported .vp.json');

    // Upload: another preset first, then each file brings the edited TF back into the editor.
    const uploaded = async (path) => {
      await page.selectOption('#preset', 'ct-bone');
      const n = await page.evaluate(() => window.lacunaViewer.frames());
      await page.setInputFiles('#tf-file', path);
      await page.waitForFunction((op) => JSON.stringify(window.lacunaViewer.state.tf.opacity.map((p) => p[1])) === op,
                                 JSON.stringify(edited.opacity.map((p) => p[1])), { timeout: 30_000 });
      await waitFullFrame(page, n);
      return page.evaluate(() => window.lacunaViewer.state.tf);
    };
    const fromJson = await uploaded(tfJson.path);
    check(JSON.stringify(fromJson.opacity) === JSON.stringify(edited.opacity) &&
          JSON.stringify(fromJson.color) === JSON.stringify(edited.color),
          'uploading the lacuna JSON gives the editor the same TF');
    const fromVp = await uploaded(vp.path);
    const near = (a, b) => a.length === b.length && a.every((p, i) => p.every((v, k) => Math.abs(v - b[i][k]) < 1e-9));
    check(near(fromVp.opacity, edited.opacity) && near(fromVp.color, edited.color) &&
          (await page.inputValue('#preset')) === '',
          'uploading the .vp.json gives the editor the same TF (x through the value domain and back, to 1e-9)');

    // A broken upload: the status line names the file and the field, the editor keeps its TF.
    {
      const bad = join(dir, 'broken.vp.json');
      writeFileSync(bad, JSON.stringify({ volumeProperties: [{ components: [{ scalarOpacity: { points: [] } }] }] }));
      const kept = await page.evaluate(() => JSON.stringify(window.lacunaViewer.state.tf));
      await page.setInputFiles('#tf-file', bad);
      await page.waitForFunction(() => document.getElementById('status').textContent.includes('broken.vp.json'),
                                 null, { timeout: 30_000 });
      const status = await page.textContent('#status');
      check(status.includes('scalarOpacity') && kept === await page.evaluate(() => JSON.stringify(window.lacunaViewer.state.tf)),
            `a broken upload is one error in the status line, the TF stays ("${status}")`);
    }

    // The session and the screenshot of the same view at twice the view's size, with the toggles
    // on (the slicer switched them off).
    for (const id of ['shading', 'clip']) {
      const n = await page.evaluate(() => window.lacunaViewer.frames());
      await page.check('#' + id);
      await waitFullFrame(page, n);
    }
    await page.selectOption('#shot-scale', '2');
    const size = (await page.textContent('#shot-size')).split('×').map(Number);
    const session = await saved('#session-save', 'viewer-session.json');
    const doc = JSON.parse(readFileSync(session.path, 'utf8'));
    check(doc.lacuna_session === 1 && doc.volume.path === volume && doc.frame.width === size[0] &&
          doc.frame.height === size[1] && doc.frame.features.shading === 'phong' &&
          doc.frame.features.clip_planes.length === 1,
          `the session names the volume, the size ${size.join('x')} and the toggles (shading ${doc.frame.features.shading}, ${doc.frame.features.clip_planes.length} clip plane)`);
    const shot = await saved('#screenshot', 'screenshot.png');
    const png = readFileSync(shot.path);
    check(png.subarray(1, 4).toString() === 'PNG' && png.readUInt32BE(16) === size[0] && png.readUInt32BE(20) === size[1],
          `the screenshot is a ${size.join('x')} PNG rendered by the server (${shot.suggested}, ${png.length} bytes)`);
    const cliPng = join(dir, 'session-cli.png');
    check(cliRender(['--session', session.path, '--out', cliPng]) === 0, 'lacuna render --session reads the saved session');
    check(Buffer.compare(readFileSync(cliPng), png) === 0,
          'lacuna render --session gives the screenshot byte for byte');
    // Open the saved session after changing the view: the page takes the session's state back
    // (camera, toggles, TF, size), and saving again writes the same file.
    {
      const n = await page.evaluate(() => window.lacunaViewer.frames());
      await page.selectOption('#view-name', 'left');
      await page.uncheck('#shading');
      await page.selectOption('#preset', 'ct-bone');
      await page.selectOption('#shot-scale', '1');
      await waitFullFrame(page, n);
      const m = await page.evaluate(() => window.lacunaViewer.frames());
      await page.setInputFiles('#session-file', session.path);
      await page.waitForFunction(() => window.lacunaViewer.state.shading === true, null, { timeout: 30_000 });
      await waitFullFrame(page, m);
      const st = await page.evaluate(() => window.lacunaViewer.state);
      check(st.camera.view === undefined && st.camera.azimuth === doc.frame.camera.azimuth_deg &&
            st.clip && (await page.inputValue('#shot-scale')) === 'session' &&
            JSON.stringify(st.tf.opacity) === JSON.stringify(doc.tf.opacity),
            `opening the session restores the camera (azimuth ${st.camera.azimuth}), the toggles, the TF and the size`);
      const again = await saved('#session-save', 'reopened-session.json');
      check(readFileSync(again.path, 'utf8') === readFileSync(session.path, 'utf8'),
            'saving the opened session writes the same file');
    }
    await page.selectOption('#shot-scale', '1');
  }

  // A second tab at the same time.
  const page2 = await context.newPage();
  page2.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  await page2.goto(url);
  await waitFullFrame(page2, 0);
  check(true, 'a second tab gets its own frames');
  await page2.close();

  // Patient orientation (issue 14): a phantom stored LPS in a server of its own. The page's view
  // menu and its clip-plane box, used as a user would, send requests whose frames are the JPEGs
  // of `lacuna render --view V --clip ...` on the same file with the settings the page sent.
  {
    const phantom = join(dir, 'phantom-lps.nrrd'), tfFile = join(dir, 'phantom.json');
    const labelFile = join(dir, 'phantom-labels.nrrd');
    writeLpsPhantom(phantom);
    writeLpsPhantom(labelFile, true);
    writeFileSync(tfFile, JSON.stringify(kPhantomTf));
    // With --labels (the frames below keep segments off, so they are `lacuna render`'s without).
    const url2 = await spawnServer(phantom, tfFile, (s) => { server2 = s; }, ['--labels', labelFile]);
    const page3 = await context.newPage();
    page3.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
    page3.on('pageerror', (e) => consoleErrors.push(String(e)));
    // What the page sent and what it got, as they went over its WebSocket, by request id.
    const sent = new Map(), received = new Map();
    page3.on('websocket', (ws) => {
      ws.on('framesent', (f) => {
        if (typeof f.payload !== 'string') return;
        const m = JSON.parse(f.payload);
        if (m.type === 'render') sent.set(m.id, m);
      });
      ws.on('framereceived', (f) => {
        if (typeof f.payload === 'string') return;
        const fr = parseFrame(Buffer.from(f.payload));
        if (fr.header.type === 'frame') received.set(fr.header.id, fr);  // not the slice panes'
      });
    });
    await page3.goto(url2);
    await waitFullFrame(page3, 0);
    const rows = await page3.evaluate(() => ['segments-row', 'overlay-row'].map(
        (id) => getComputedStyle(document.getElementById(id)).display));
    check(rows.every((d) => d === 'flex'), `with --labels the segments and overlay rows show (${rows})`);
    const setOverlay = (x) => page3.evaluate((x) => {
      const el = document.getElementById('overlay-opacity');
      el.value = String(x);
      el.dispatchEvent(new Event('input'));
    }, x);
    await setOverlay(0);
    // The slice panes in 3D Slicer's orientation on this file stored LPS: at the full range the
    // brightest pixels are the right marker (220) on the screen's left in axial and coronal, and
    // in sagittal the front marker (160), on the screen's left (the nose points left).
    await page3.selectOption('#wl-preset', 'full');
    const settled3 = () => page3.waitForFunction(() => {
      const s = window.lacunaViewer.slices();
      return ['axial', 'coronal', 'sagittal'].every((p) => s[p].count > 0 && s[p].settled);
    }, null, { timeout: 30_000 });
    const paneStats = () => page3.evaluate(() => {
      const out = {};
      for (const p of ['axial', 'coronal', 'sagittal']) {
        const sl = window.lacunaViewer.slices()[p], f = sl.fit;
        const w = Math.floor(f.s * sl.header.width), h = Math.floor(f.s * sl.header.height);
        const d = document.querySelector(`#pane-${p} canvas`).getContext('2d').getImageData(f.ox, f.oy, w, h).data;
        // grey: the JPEG's chroma keeps r, g, b within a few steps; the crosshair and the label
        // colours (saturation 0.65) are far apart
        const grey = (i) => Math.max(d[i], d[i + 1], d[i + 2]) - Math.min(d[i], d[i + 1], d[i + 2]) < 24;
        let max = 0;
        for (let i = 0; i < d.length; i += 4) if (grey(i)) max = Math.max(max, d[i]);
        let n = 0, sx = 0;
        for (let i = 0; i < d.length; i += 4) {
          if (grey(i) && d[i] >= 0.85 * max) { n++; sx += (i / 4) % w; }
        }
        let coloured = 0;  // label overlay pixels: neither grey nor the crosshair's exact yellow
        for (let i = 0; i < d.length; i += 4) {
          if (!grey(i) && !(d[i] === 255 && d[i + 1] === 204 && d[i + 2] === 0)) coloured++;
        }
        out[p] = { n, x: n ? sx / n / w : 0.5, max, coloured };
      }
      return out;
    });
    await settled3();
    const brightest = await paneStats();
    for (const [p, what] of [['axial', 'the right marker'], ['coronal', 'the right marker'], ['sagittal', 'the front marker']]) {
      const b = brightest[p];
      check(b.n > 0 && b.max > 100 && b.x < 0.4,
            `${p} pane: ${what} on the screen's left (${b.n} px at ${b.x.toFixed(2)} of the width)`);
    }
    // The label overlay (opacity 0 so far: no coloured pixel) and the probe's label: a click on
    // the right marker's centre (11, -2, 0) in the axial pane reads label 1.
    await setOverlay(0.5);
    await settled3();
    const withOverlay = await paneStats();
    check(brightest.axial.coloured === 0 && withOverlay.axial.coloured > 20,
          `the overlay slider blends the labels over the slices (${brightest.axial.coloured} -> ${withOverlay.axial.coloured} coloured px)`);
    const ax = (await page3.evaluate(() => window.lacunaViewer.slices())).axial.header;
    const marker = [11, -2, 0], d = marker.map((x, a) => x - ax.origin[a]);
    const dot3 = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const at = await page3.evaluate(([c, r]) => window.lacunaViewer.sliceClient('axial', c, r),
                                    [dot3(d, ax.u) / dot3(ax.u, ax.u), dot3(d, ax.v) / dot3(ax.v, ax.v)]);
    await page3.mouse.click(at.x, at.y);
    await page3.waitForFunction(() => {
      const pr = window.lacunaViewer.probe();
      return pr && JSON.stringify(pr.point) === JSON.stringify(window.lacunaViewer.state.point);
    }, null, { timeout: 30_000 });
    const pr = await page3.evaluate(() => window.lacunaViewer.probe());
    const readout = await page3.textContent('#probe');
    check(pr.label === 1 && readout.includes('label 1') && pr.value > 200,
          `the probe readout names the label under the crosshair: "${readout.replace(/\n/g, ' | ')}"`);
    await setOverlay(0);
    await settled3();
    // The newest full-resolution frame and the request it answers.
    const latest = () => {
      const id = Math.max(...[...received.values()].filter((f) => !f.header.preview).map((f) => f.header.id));
      return { req: sent.get(id), frame: received.get(id) };
    };
    // The CLI's image for a request, through the server's JPEG encoder.
    const cliJpeg = (req, planes) => {
      const tag = `${req.id}-${planes.length}-${planes.flat().join('_')}`;
      const tf = join(dir, `tf-${tag}.json`), png = join(dir, `cli-${tag}.png`), jpg = join(dir, `cli-${tag}.jpg`);
      writeFileSync(tf, JSON.stringify(req.tf));
      const flags = ['render', phantom, '--tf', tf, '--renderer', req.renderer, '--accel', req.accel,
                     '--width', String(req.width), '--height', String(req.height),
                     '--view', req.camera.view, '--zoom', String(req.camera.zoom), '--step', String(req.step),
                     '--ert', req.ert ? '0.99' : '1'];
      for (const p of planes) flags.push(`--clip=${p.join(',')}`);
      execFileSync(args.lacuna, [...flags, '--out', png], { stdio: 'ignore' });
      execFileSync(args.jpeg, [png, jpg], { stdio: 'ignore' });
      return readFileSync(jpg);
    };
    // The red right marker's pixels in the page's image, and their mean x (a fraction of the width).
    const redMarker = () => page3.evaluate(() => {
      const im = document.getElementById('frame');
      const c = document.createElement('canvas');
      c.width = im.naturalWidth;
      c.height = im.naturalHeight;
      const g = c.getContext('2d');
      g.drawImage(im, 0, 0);
      const d = g.getImageData(0, 0, c.width, c.height).data;
      let n = 0, sx = 0;
      for (let p = 0; p < d.length; p += 4) {
        if (d[p] > 150 && d[p + 1] < 90 && d[p + 2] < 90) { n++; sx += (p / 4) % c.width; }
      }
      return { n, x: n ? sx / n / c.width : 0.5 };
    });
    const firstFrame = latest().frame.jpeg;
    const steps = [
      { view: 'left', clip: '' },
      { view: 'anterior', clip: '' },
      { view: 'anterior', clip: '-1,0,0,0' },
      { view: 'superior', clip: '-1,0,0,0; 0,0,-1,-4' },
    ];
    let previous = null;
    for (const st of steps) {
      // As a user: type the planes (Enter commits the box), pick the view from the menu.
      if (st.clip !== await page3.inputValue('#clip-planes')) {
        const n = await page3.evaluate(() => window.lacunaViewer.frames());
        await page3.fill('#clip-planes', st.clip);
        await page3.press('#clip-planes', 'Enter');
        await waitFullFrame(page3, n);
      }
      if (st.view !== await page3.inputValue('#view-name')) {
        const n = await page3.evaluate(() => window.lacunaViewer.frames());
        await page3.selectOption('#view-name', st.view);
        await waitFullFrame(page3, n);
      }
      const { req, frame } = latest();
      const planes = st.clip ? st.clip.split(';').map((t) => t.split(',').map(Number)) : [];
      check(req.camera.view === st.view && req.camera.azimuth === undefined &&
            JSON.stringify(req.clip_planes) === JSON.stringify(planes),
            `the page sends view ${st.view} by name with clip planes ${JSON.stringify(req.clip_planes)}`);
      check(frame.header.width === req.width && frame.header.height === req.height && !(frame.header.reduced > 1),
            `the frame has the requested size (${req.width}x${req.height})`);
      const cli = cliJpeg(req, planes);
      check(Buffer.compare(frame.jpeg, cli) === 0,
            `view ${st.view}${st.clip ? ', clip ' + st.clip : ''}: the frame is lacuna render's image byte for byte`);
      check(Buffer.compare(frame.jpeg, previous || firstFrame) !== 0, 'and it differs from the frame before it');
      previous = frame.jpeg;
      if (st.view === 'anterior') {
        // Seen from the front the patient's right is on the screen's left; keeping x <= 0 (RAS)
        // removes it, whatever the file's voxel order.
        const red = await redMarker();
        if (!st.clip) check(red.n > 20 && red.x < 0.5, `the right marker shows on the screen's left (${red.n} px at ${red.x.toFixed(2)})`);
        else check(red.n === 0, `the clip plane x <= 0 removes the patient's right (${red.n} red px)`);
        if (st.clip) {
          check(Buffer.compare(frame.jpeg, cliJpeg(req, [[1, 0, 0, 0]])) !== 0,
                'the mirrored plane gives another picture (the comparison sees the side)');
        }
      }
    }
    await page3.close();
    server2.removeAllListeners('exit');
    const exited2 = new Promise((resolve) => server2.once('exit', (code) => resolve(code)));
    server2.kill('SIGINT');
    check(await exited2 === 0, 'the orientation server stops cleanly');
    server2 = null;
  }

  // 4D files (issue 18 item 6): a NIfTI series of three volumes in a server of its own, started
  // without --frame (volume 0). The frame selector shows; choosing volume 2 makes the server read
  // it and every later frame is of it: the page's frame is, byte for byte, `lacuna render
  // --session` of the session the page then saves, which names frame 2; and it differs from the
  // frame of volume 0.
  {
    const series = join(dir, 'series.nii');
    write4dNifti(series, [24, 22, 20], 3);
    let server3 = null;
    const url3 = await spawnServer(series, 'mr-default', (s) => { server3 = s; });
    server2 = server3;  // fail() kills it
    const page4 = await context.newPage();
    page4.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
    page4.on('pageerror', (e) => consoleErrors.push(String(e)));
    const sent = new Map(), received = new Map(), frameMessages = [];
    page4.on('websocket', (ws) => {
      ws.on('framesent', (f) => {
        if (typeof f.payload !== 'string') return;
        const m = JSON.parse(f.payload);
        if (m.type === 'render') sent.set(m.id, m);
        if (m.type === 'volume_frame') frameMessages.push(m);
      });
      ws.on('framereceived', (f) => {
        if (typeof f.payload === 'string') return;
        const fr = parseFrame(Buffer.from(f.payload));
        if (fr.header.type === 'frame') received.set(fr.header.id, fr);
      });
    });
    const latest = () => {
      const id = Math.max(...[...received.values()].filter((f) => !f.header.preview).map((f) => f.header.id));
      return { req: sent.get(id), frame: received.get(id) };
    };
    await page4.goto(url3);
    await waitFullFrame(page4, 0);
    const selector = await page4.evaluate(() => ({
      display: getComputedStyle(document.getElementById('frame-row')).display,
      max: document.getElementById('volume-frame').max, value: document.getElementById('volume-frame').value,
      frames: window.lacunaViewer.hello().frames }));
    check(selector.display === 'flex' && selector.max === '2' && selector.value === '0' && selector.frames === 3,
          `a 4D file shows the frame selector (volumes 0..${selector.max}, showing ${selector.value})`);
    const first = latest().frame.jpeg;
    const n = await page4.evaluate(() => window.lacunaViewer.frames());
    await page4.fill('#volume-frame-n', '2');
    await page4.dispatchEvent('#volume-frame-n', 'change');
    await page4.waitForFunction(() => window.lacunaViewer.hello().frame === 2, null, { timeout: 30_000 });
    await waitFullFrame(page4, n);
    const { req, frame } = latest();
    check(frameMessages.length === 1 && frameMessages[0].frame === 2 &&
          (await page4.inputValue('#volume-frame')) === '2',
          'choosing volume 2 sends one volume_frame message and the slider follows');
    check(Buffer.compare(frame.jpeg, first) !== 0, 'the frame of volume 2 differs from that of volume 0');
    const [dl] = await Promise.all([page4.waitForEvent('download', { timeout: 60_000 }), page4.click('#session-save')]);
    const sessionPath = join(dir, 'series-session.json');
    await dl.saveAs(sessionPath);
    const doc = JSON.parse(readFileSync(sessionPath, 'utf8'));
    check(doc.volume.path === series && doc.volume.frame === 2, `the saved session names frame ${doc.volume.frame}`);
    // The session at the frame's size: the CLI's image through the server's JPEG encoder.
    doc.frame.width = req.width;
    doc.frame.height = req.height;
    const sized = join(dir, 'series-session-sized.json'), png = join(dir, 'series.png'), jpg = join(dir, 'series.jpg');
    writeFileSync(sized, JSON.stringify(doc));
    execFileSync(args.lacuna, ['render', '--session', sized, '--out', png], { stdio: 'ignore' });
    execFileSync(args.jpeg, [png, jpg], { stdio: 'ignore' });
    check(Buffer.compare(frame.jpeg, readFileSync(jpg)) === 0,
          'the frame of volume 2 is lacuna render --session (frame 2) byte for byte');
    await page4.close();
    server3.removeAllListeners('exit');
    const exited3 = new Promise((resolve) => server3.once('exit', (code) => resolve(code)));
    server3.kill('SIGINT');
    check(await exited3 === 0, 'the 4D server stops cleanly');
    server2 = null;
  }

  await page.screenshot({ path: args.screenshot });
  console.log(`wrote ${args.screenshot}`);
  check(consoleErrors.length === 0, `no console errors${consoleErrors.length ? ': ' + consoleErrors.join(' | ') : ''}`);
  await browser.close();
  browser = null;

  // Ctrl-C: the server closes its connections and exits 0.
  server.removeAllListeners('exit');
  const exited = new Promise((resolve) => server.once('exit', (code, signal) => resolve({ code, signal })));
  server.kill('SIGINT');
  const { code, signal } = await exited;
  check(code === 0, `SIGINT stops the server cleanly (exit ${code}${signal ? ', ' + signal : ''})`);
  server = null;
  clearTimeout(watchdog);
  rmSync(dir, { recursive: true, force: true });
  console.log('e2e.viewer: PASS');
} catch (e) {
  fail(e && e.stack ? e.stack : String(e));
}
