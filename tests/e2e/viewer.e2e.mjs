// End-to-end test of the browser viewer (ctest: e2e.viewer): starts `lacuna serve` on a generated
// volume on a free port, loads the page in Debian's headless chromium through playwright-core,
// waits for a frame, drags a TF opacity point, and checks that the image changes, that the
// overlay reports the TF-change time, that a second tab is served, that the page logged no
// console errors, and that Ctrl-C (SIGINT) stops the server cleanly. Saves a screenshot of the
// viewer to --screenshot (default docs/images/viewer.png, the README picture; ctest passes a path in
// the build folder so a test run leaves the checkout untouched).
//
// Usage: node tests/e2e/viewer.e2e.mjs [--lacuna build/lacuna] [--chromium /usr/bin/chromium]
//                                       [--screenshot docs/images/viewer.png]
import { spawn, execFileSync } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';

const args = { lacuna: 'build/lacuna', chromium: '/usr/bin/chromium', screenshot: 'docs/images/viewer.png' };
for (let i = 2; i + 1 < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];

const dir = mkdtempSync(join(tmpdir(), 'lacuna-e2e-'));
let server = null;
let browser = null;
const watchdog = setTimeout(() => fail('timed out after 150 s'), 150_000);

function fail(message) {
  console.error(`e2e.viewer: FAIL: ${message}`);
  if (server) server.kill('SIGKILL');
  if (browser) browser.close().catch(() => {});
  rmSync(dir, { recursive: true, force: true });
  process.exit(1);
}
function check(cond, message) { if (!cond) fail(message); else console.log(`ok - ${message}`); }

// The server prints its URL once it listens ("lacuna viewer: http://127.0.0.1:PORT/ ...").
function startServer(volume) {
  return new Promise((resolve, reject) => {
    server = spawn(args.lacuna, ['serve', volume, '--port', '0', '--tf', 'mr-default'],
                   { stdio: ['ignore', 'pipe', 'pipe'] });
    let out = '';
    server.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/lacuna viewer: (http:\/\/127\.0\.0\.1:\d+\/)/);
      if (m) resolve(m[1]);
    });
    server.stderr.on('data', (d) => process.stderr.write(d));
    server.on('exit', (code) => reject(new Error(`lacuna serve exited with ${code}: ${out}`)));
  });
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

  await page.goto(url);
  await waitFullFrame(page, 0);
  check(true, 'the page shows a frame');
  const accels = await page.$$eval('#accel option', (os) => os.map((o) => o.value));
  check(accels.includes('bitfield') && accels.includes('none'), `accel selector lists ${accels.join(', ')}`);

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

  // A second tab at the same time.
  const page2 = await context.newPage();
  page2.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  await page2.goto(url);
  await waitFullFrame(page2, 0);
  check(true, 'a second tab gets its own frames');
  await page2.close();

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
