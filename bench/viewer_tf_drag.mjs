// Frame rate of the browser viewer while a TF point is dragged, per skipping structure, against
// the same structure while the camera is dragged (docs/viewer.md). Drives the real page in
// Debian's headless chromium (playwright-core, `npm ci`), so the numbers include the WebSocket,
// JPEG encoding and decoding: what a user sees.
//
// Usage: node bench/viewer_tf_drag.mjs [--volume /usr/share/mricron/templates/ch2better.nii.gz]
//          [--tf mr-brain] [--accels bitfield,minmax,boolean,distance,kdtree] [--seconds 4]
//          [--size 640x480] [--lacuna build/lacuna] [--chromium /usr/bin/chromium] [--threads 0]
import { spawn } from 'node:child_process';
import { chromium } from 'playwright-core';

const args = { volume: '/usr/share/mricron/templates/ch2better.nii.gz', tf: 'mr-brain',
               accels: 'bitfield,minmax,boolean,distance,kdtree', seconds: '4', size: '640x480',
               lacuna: 'build/lacuna', chromium: '/usr/bin/chromium', threads: '0' };
for (let i = 2; i + 1 < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
const [vw, vh] = args.size.split('x').map(Number);
const seconds = Number(args.seconds);

const server = spawn(args.lacuna, ['serve', args.volume, '--port', '0', '--tf', args.tf,
                                   '--threads', args.threads], { stdio: ['ignore', 'pipe', 'inherit'] });
const url = await new Promise((resolve, reject) => {
  let out = '';
  server.stdout.on('data', (d) => {
    out += d;
    const m = out.match(/lacuna viewer: (http:\S+)/);
    if (m) resolve(m[1]);
  });
  server.on('exit', (c) => reject(new Error(`lacuna serve exited ${c}`)));
});

const browser = await chromium.launch({ executablePath: args.chromium, headless: true,
                                        args: ['--no-sandbox', '--disable-gpu'] });
// The panel is 316 px wide: the view gets size.
const page = await browser.newPage({ viewport: { width: vw + 316, height: vh } });
await page.goto(url);

const frames = () => page.evaluate(() => window.lacunaViewer.frames());
async function settle() {
  const n = await frames();
  await page.waitForFunction((k) => window.lacunaViewer.frames() > k &&
      !document.getElementById('o-frame').textContent.includes('preview'), n, { timeout: 600_000 });
  await page.waitForTimeout(500);
}
// Moves the mouse from (x, y) along a zig-zag for `seconds`, one move every ~16 ms; returns the
// frame headers that arrived meanwhile.
async function drag(x, y, dx, dy) {
  const t0 = await page.evaluate(() => performance.now());
  await page.mouse.move(x, y);
  await page.mouse.down();
  const end = Date.now() + seconds * 1000;
  for (let k = 0; Date.now() < end; k++) {
    const s = Math.sin(k / 15);
    await page.mouse.move(x + dx * s, y + dy * s);
    await page.waitForTimeout(16);
  }
  const t1 = await page.evaluate(() => performance.now());
  await page.mouse.up();
  const log = await page.evaluate(([a, b]) => window.lacunaViewer.frameLog.filter((f) => f.t > a && f.t <= b), [t0, t1]);
  return { log, seconds: (t1 - t0) / 1000 };
}
const mean = (xs) => (xs.length ? xs.reduce((a, b) => a + b, 0) / xs.length : 0);

await settle();
console.log(`${args.volume}, TF ${args.tf}, view ${vw}x${vh}, ${seconds} s per drag`);
console.log('accel      build[ms]  orbit fps  orbit frame[ms]  TF-drag fps  TF-drag frame[ms]  TF update[ms]  TF latency[ms]  preview');
for (const accel of args.accels.split(',')) {
  await page.selectOption('#accel', accel);
  await settle();
  const build = await page.evaluate(() => {
    const l = window.lacunaViewer.frameLog;
    return Math.max(0, ...l.slice(-5).map((f) => f.accel_build_ms));
  });
  const orbit = await drag(vw / 2, vh / 2, 120, 0);
  await settle();
  const p = await page.evaluate(() => {
    const tf = window.lacunaViewer.state.tf;
    // the opacity point with the largest opacity below 1, not at the ends: the one a user drags
    let best = 1;
    tf.opacity.forEach((q, i) => { if (i > 0 && i < tf.opacity.length - 1 && q[1] >= tf.opacity[best][1]) best = i; });
    return window.lacunaViewer.opacityPointClient(best);
  });
  const tfd = await drag(p.x, p.y, 0, 25);
  await settle();
  const tfFrames = tfd.log.filter((f) => f.tf_changed);
  const prev = tfd.log.length ? `${tfd.log[tfd.log.length - 1].width}x${tfd.log[tfd.log.length - 1].height}` : '-';
  console.log(`${accel.padEnd(10)} ${build.toFixed(0).padStart(9)} ${(orbit.log.length / orbit.seconds).toFixed(1).padStart(10)}` +
              ` ${mean(orbit.log.map((f) => f.frame_ms)).toFixed(1).padStart(16)}` +
              ` ${(tfd.log.length / tfd.seconds).toFixed(1).padStart(12)} ${mean(tfd.log.map((f) => f.frame_ms)).toFixed(1).padStart(18)}` +
              ` ${mean(tfFrames.map((f) => f.tf_update_ms)).toFixed(2).padStart(14)} ${mean(tfFrames.map((f) => f.tf_latency_ms)).toFixed(1).padStart(15)}  ${prev}`);
}
await browser.close();
server.kill('SIGINT');
