// lacuna viewer: the page side of `lacuna serve` (docs/viewer.md). Plain JavaScript, no
// dependencies. The server renders; this page sends the whole view state with every request
// and shows the JPEG frames it gets back.
//
// Flow control: at most one request is in flight; input that arrives meanwhile marks the view
// dirty and the newest state goes out when the frame arrives (the server also keeps only the
// latest request per tab). While the camera moves or a TF point is dragged the page asks for
// previews (the server renders them at reduced resolution); 150 ms after the last input it asks
// for the full-resolution frame.
//
// Slice panes (axial, coronal, sagittal; docs/viewer.md "Slice views"): each asks the server for
// its plane through the crosshair point with a `slice` message and draws the JPEG it gets back,
// letterboxed, with the crosshair on top. The reply's header maps pixels to the world (pixel
// (c, r) is at origin + c u + r v, RAS mm), so a click is a world point: it becomes the crosshair,
// the other planes are fetched through it, and a `probe` message reads the value there. Each pane
// has at most one slice in flight (newest state when it arrives), as the 3D view does.
//
// Saving work (docs/viewer.md "Saving work"): the TF buttons send `tf_export` (the server writes
// lacuna TF JSON or Slicer .vp.json with the library's writers) and `tf_import` (an uploaded file
// read by the library's readers, answered as lacuna TF JSON for the editor); the screenshot button
// sends `screenshot` (the server renders the view at full resolution and sends the PNG); the
// session button sends `session` (the server writes the session file `lacuna render --session`
// reads). Each answer becomes a download. Screenshot and session carry the same view state at the
// same size, so the session renders to the screenshot's bytes.
'use strict';

(() => {
  const $ = (id) => document.getElementById(id);
  const view = $('view'), img = $('frame');
  const tfCanvas = $('tf'), colorCanvas = $('colors');

  // Named anatomical views (lacuna/views.h): azimuth about superior from the anterior view.
  const kViews = { anterior: [0, 0], posterior: [180, 0], left: [90, 0], right: [270, 0],
                   superior: [0, 90], inferior: [0, -90] };

  const state = {
    camera: { azimuth: 30, elevation: 15, zoom: 1, pan: [0, 0] },
    renderer: 'march',
    accel: 'grid',
    ert: true,
    shading: false,
    clip: false,
    clipPlanes: [],  // world planes [nx, ny, nz, d] in patient RAS mm (lacuna render --clip)
    segments: false,
    hide: '',
    step: 0.5,
    // TF in the normalized domain: x in [0,1] across the volume's visualization range (or
    // tf.range when set). color: [x, r, g, b]; opacity: [x, a].
    tf: null,
    // Slice panes: the crosshair (world RAS mm) and the grey mapping of every pane.
    point: [0, 0, 0],
    window: 1,
    level: 0.5,
    wlPreset: 'vis',
    interpolation: 'trilinear',
    overlayOpacity: 0.4,
    volumeFrame: 0,  // the volume of a 4D file the server shows (hello.frame)
  };
  let hello = null;
  let ws = null;
  let nextId = 1;
  let inFlight = null;      // id of the request awaiting its frame
  let dirty = false;        // the view changed since the last request went out
  let dirtyPreview = false;
  let interacting = false;  // pointer held on the view or a TF point
  let idleTimer = 0;
  let frames = 0;
  let lastFrameAt = 0, fps = 0;
  let lastTfReport = null;
  let currentUrl = null, pendingUrl = null;
  const frameLog = [];      // the last 2000 frame headers with their arrival time (scripts)
  let selectedStop = -1;

  // ---- connection -------------------------------------------------------------------------
  function connect() {
    ws = new WebSocket(`ws://${location.host}/ws`);
    ws.binaryType = 'arraybuffer';
    ws.onmessage = (ev) => {
      if (typeof ev.data === 'string') onText(JSON.parse(ev.data));
      else onBinary(ev.data);
    };
    ws.onclose = () => {
      setStatus('disconnected: is `lacuna serve` still running?');
      inFlight = null;
      shotInFlight = null;
      fileRequests.clear();
      probeInFlight = null;
      for (const pane of Object.values(panes)) pane.inFlight = null;
    };
  }

  function onText(msg) {
    if (msg.type === 'hello') return onHello(msg);
    if (msg.type === 'probe') return onProbe(msg);
    if (msg.type === 'session' || msg.type === 'tf_export' || msg.type === 'tf_import') return onFile(msg);
    if (msg.type === 'session_import') return onSessionOpened(msg);
    if (msg.type === 'volume_frame') return onVolumeFrame(msg);
    if (msg.type === 'error') {
      // The server rejected a request: show it (not a console error: the page stays usable).
      setStatus('server: ' + msg.message);
      if (msg.id !== null && fileRequests.has(msg.id)) fileRequests.delete(msg.id);
      if (msg.id !== null && msg.id === shotInFlight) { shotInFlight = null; $('screenshot').disabled = false; }
      if (msg.id !== null && msg.id === inFlight) { inFlight = null; flush(); }
      for (const pane of Object.values(panes)) {
        if (msg.id !== null && msg.id === pane.inFlight) { pane.inFlight = null; flushSlice(pane); }
      }
      if (msg.id !== null && msg.id === probeInFlight) { probeInFlight = null; flushProbe(); }
      if (msg.id !== null && msg.id === framePending.id) { framePending = { id: null, frame: null }; showFrameSelector(); }
    }
  }

  function onHello(msg) {
    hello = msg;
    showTitle();
    showFrameSelector();
    fillSelect($('renderer'), msg.renderers, state.renderer);
    state.renderer = $('renderer').value;
    fillSelect($('accel'), msg.accels, msg.accels.includes('grid') ? 'grid' : msg.accels[0]);
    state.accel = $('accel').value;
    // Segments only when the server loaded a label volume (`lacuna serve ... --labels FILE`).
    $('segments-row').hidden = !(msg.labels > 0);
    const presets = $('preset');
    for (const name of Object.keys(msg.presets)) {
      const o = document.createElement('option');
      o.value = o.textContent = name;
      presets.appendChild(o);
    }
    setTf(msg.tf);
    presets.value = msg.presets[msg.tf.name] ? msg.tf.name : '';
    // Session files name the server's volume file (a server without one cannot write them).
    $('session-save').disabled = !msg.session;
    $('session-open').disabled = !msg.session;
    showShotSize();
    setStatus('');
    request(false);
    startSlices(msg);
  }

  function showTitle() {
    const v = hello.volume;
    $('title').textContent = `lacuna · ${v.name} (${v.dims.join('×')} ${v.type})`;
  }

  // ---- the frame selector of a 4D file (hello.frames > 1) -------------------------------------
  // The server reads the chosen volume and answers every tab with its info; the 3D view, the
  // slices, the probe and the TF editor's histogram then follow (session files name the frame).
  function showFrameSelector() {
    const n = hello.frames || 1;
    state.volumeFrame = hello.frame || 0;
    $('frame-row').hidden = !(n > 1 && (hello.messages || []).includes('volume_frame'));
    for (const el of [$('volume-frame'), $('volume-frame-n')]) {
      el.max = String(n - 1);
      el.value = String(state.volumeFrame);
    }
    $('volume-frames').textContent = `of ${n}`;
  }
  function chooseFrame(value) {
    const k = Math.round(Number(value));
    if (!hello || !Number.isFinite(k) || k < 0 || k >= (hello.frames || 1)) return showFrameSelector();
    $('volume-frame').value = $('volume-frame-n').value = String(k);
    if (k === state.volumeFrame || k === framePending.frame || !ws || ws.readyState !== WebSocket.OPEN) return;
    setStatus(`reading frame ${k}…`);
    framePending = { id: nextId++, frame: k };
    ws.send(JSON.stringify({ type: 'volume_frame', id: framePending.id, frame: k }));
  }
  let framePending = { id: null, frame: null };  // the volume_frame message awaiting its answer
  $('volume-frame').addEventListener('change', (e) => chooseFrame(e.target.value));
  $('volume-frame-n').addEventListener('change', (e) => chooseFrame(e.target.value));
  function onVolumeFrame(msg) {
    framePending = { id: null, frame: null };
    hello.volume = msg.volume;
    hello.histogram = msg.histogram;
    hello.frame = msg.frame;
    hello.frames = msg.frames;
    showTitle();
    showFrameSelector();
    drawTf();
    setStatus('');
    request(false);
    requestSlices();
    requestProbe();
  }

  // Binary messages: a frame of the 3D view or a slice of a pane, by the header's type.
  function onBinary(buf) {
    const bytes = new Uint8Array(buf);
    const n = bytes[0] | (bytes[1] << 8) | (bytes[2] << 16) | (bytes[3] << 24);
    const header = JSON.parse(new TextDecoder().decode(bytes.subarray(4, 4 + n)));
    if (header.type === 'slice') onSlice(header, bytes.subarray(4 + n));
    else if (header.type === 'screenshot') onScreenshot(header, bytes.subarray(4 + n));
    else onFrame(header, bytes.subarray(4 + n));
  }

  function onFrame(header, jpeg) {
    const url = URL.createObjectURL(new Blob([jpeg], { type: 'image/jpeg' }));
    // A frame still decoding when a newer one arrives is superseded: free its blob.
    const superseded = pendingUrl;
    pendingUrl = url;
    img.onload = () => {
      if (currentUrl) URL.revokeObjectURL(currentUrl);
      currentUrl = url;
      pendingUrl = null;
      frames += 1;
      document.body.dataset.frames = String(frames);
    };
    img.src = url;
    if (superseded) URL.revokeObjectURL(superseded);
    const now = performance.now();
    if (lastFrameAt) fps = 0.8 * fps + 0.2 * (1000 / Math.max(1, now - lastFrameAt));
    lastFrameAt = now;
    showStats(header);
    frameLog.push({ t: now, ...header });
    if (frameLog.length > 2000) frameLog.shift();
    if (header.id === inFlight) inFlight = null;
    flush();
  }

  // ---- requests ---------------------------------------------------------------------------
  // Marks the view as changed; preview while the user is interacting.
  function request(preview) {
    dirty = true;
    dirtyPreview = preview;
    clearTimeout(idleTimer);
    if (preview) idleTimer = setTimeout(() => { if (!interacting) request(false); }, 150);
    flush();
  }

  // The 3D view's size in device pixels (at most 2 per CSS pixel and max_side).
  function viewSize() {
    const dpr = Math.min(window.devicePixelRatio || 1, 2);
    const max = hello ? hello.limits.max_side : 2048;
    return [Math.max(1, Math.min(max, Math.round(view.clientWidth * dpr))),
            Math.max(1, Math.min(max, Math.round(view.clientHeight * dpr)))];
  }
  // The view state every render, screenshot and session message carries.
  function viewState(type, id, [w, h]) {
    return {
      type, id, width: w, height: h,
      camera: state.camera, renderer: state.renderer, accel: state.accel,
      ert: state.ert, step: state.step, tf: state.tf, shading: state.shading, clip: state.clip,
      clip_planes: state.clipPlanes, segments: state.segments, hide: state.hide,
    };
  }

  function flush() {
    if (!dirty || inFlight !== null || !ws || ws.readyState !== WebSocket.OPEN || !state.tf) return;
    const id = nextId++;
    ws.send(JSON.stringify({ ...viewState('render', id, viewSize()), preview: dirtyPreview }));
    inFlight = id;
    dirty = false;
  }

  // ---- saving work: TF files, screenshot, session --------------------------------------------
  const fileRequests = new Map();  // id -> the file name the answer is saved as
  let shotInFlight = null;
  const safeName = (name) => (name || '').replace(/[^A-Za-z0-9._-]+/g, '-').replace(/^[-.]+/, '') || 'tf';
  // The screenshot's (and the session's) size: the view's times the menu's factor, both sides
  // scaled alike and kept within max_side.
  let sessionSize = null;  // the size of the session opened last (the image size menu's "session")
  function shotSize() {
    if ($('shot-scale').value === 'session' && sessionSize) return sessionSize.slice();
    const [w, h] = viewSize(), max = hello ? hello.limits.max_side : 2048;
    const k = Math.min(Number($('shot-scale').value) || 1, max / w, max / h);
    return [Math.max(1, Math.round(w * k)), Math.max(1, Math.round(h * k))];
  }
  function showShotSize() { $('shot-size').textContent = shotSize().join('×'); }
  function download(blob, name) {
    const a = document.createElement('a');
    a.href = URL.createObjectURL(blob);
    a.download = name;
    document.body.appendChild(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(a.href), 60_000);
  }
  function sendFileRequest(msg, name) {
    if (!ws || ws.readyState !== WebSocket.OPEN || !state.tf) return;
    fileRequests.set(msg.id, name);
    ws.send(JSON.stringify(msg));
  }
  function onFile(msg) {
    const name = fileRequests.get(msg.id);
    fileRequests.delete(msg.id);
    if (msg.type === 'tf_import') {
      setTf(msg.tf);
      $('preset').value = '';
      setStatus(`loaded ${name}`);
      request(false);
      return;
    }
    download(new Blob([msg.text], { type: 'application/json' }), name || 'lacuna.json');
    setStatus('');
  }
  function onScreenshot(header, png) {
    if (header.id === shotInFlight) shotInFlight = null;
    download(new Blob([png], { type: 'image/png' }), `lacuna-${header.width}x${header.height}.png`);
    setStatus(`screenshot ${header.width}×${header.height}: ${header.frame_ms.toFixed(0)} ms`);
    $('screenshot').disabled = false;
  }
  $('tf-download').addEventListener('click', () => {
    const id = nextId++;
    sendFileRequest({ type: 'tf_export', id, format: 'lacuna', tf: state.tf }, safeName(state.tf.name) + '.json');
  });
  $('tf-slicer').addEventListener('click', () => {
    const id = nextId++;
    sendFileRequest({ type: 'tf_export', id, format: 'slicer', tf: state.tf }, safeName(state.tf.name) + '.vp.json');
  });
  $('tf-upload').addEventListener('click', () => $('tf-file').click());
  $('tf-file').addEventListener('change', async (e) => {
    const file = e.target.files[0];
    e.target.value = '';
    if (!file) return;
    const text = await file.text();
    sendFileRequest({ type: 'tf_import', id: nextId++, name: file.name, text }, file.name);
  });
  $('shot-scale').addEventListener('change', showShotSize);
  $('screenshot').addEventListener('click', () => {
    if (shotInFlight !== null || !ws || ws.readyState !== WebSocket.OPEN || !state.tf) return;
    const id = nextId++;
    const size = shotSize();
    ws.send(JSON.stringify(viewState('screenshot', id, size)));
    shotInFlight = id;
    $('screenshot').disabled = true;
    setStatus(`rendering a ${size.join('×')} screenshot…`);
  });
  // Opening a session: the server answers the view state that renders its frame exactly (or an
  // error naming what the page cannot reproduce); the page takes it over as if the user had set
  // it, and its size becomes the image size menu's "session" entry.
  $('session-open').addEventListener('click', () => $('session-file').click());
  $('session-file').addEventListener('change', async (e) => {
    const file = e.target.files[0];
    e.target.value = '';
    if (!file) return;
    const text = await file.text();
    sendFileRequest({ type: 'session_import', id: nextId++, name: file.name, text }, file.name);
  });
  function onSessionOpened(msg) {
    const name = fileRequests.get(msg.id);
    fileRequests.delete(msg.id);
    const v = msg.view;
    state.camera = v.camera;
    $('view-name').value = v.camera.view || '';
    state.renderer = v.renderer;
    $('renderer').value = v.renderer;
    state.accel = v.accel;
    $('accel').value = v.accel;
    state.ert = v.ert;
    $('ert').checked = v.ert;
    state.step = v.step;
    $('step').value = String(v.step);
    $('step-value').textContent = String(v.step);
    state.shading = v.shading;
    $('shading').checked = v.shading;
    state.clip = v.clip;
    $('clip').checked = v.clip;
    state.clipPlanes = v.clip_planes;
    $('clip-planes').value = v.clip_planes.map((p) => p.join(',')).join('; ');
    $('clip-planes').classList.remove('invalid');
    noSegments();
    setTf(v.tf);
    $('preset').value = '';
    sessionSize = [v.width, v.height];
    let opt = $('shot-scale').querySelector('option[value="session"]');
    if (!opt) {
      opt = document.createElement('option');
      opt.value = 'session';
      $('shot-scale').appendChild(opt);
    }
    opt.textContent = `session (${v.width}×${v.height})`;
    $('shot-scale').value = 'session';
    showShotSize();
    setStatus(`opened ${name}`);
    request(false);
  }
  $('session-save').addEventListener('click', () => {
    const id = nextId++;
    sendFileRequest(viewState('session', id, shotSize()), 'lacuna-session.json');
  });

  // ---- overlay ----------------------------------------------------------------------------
  function setStatus(text) {
    $('status').textContent = text;
    $('status').style.display = text ? '' : 'none';
  }

  function showStats(h) {
    $('o-frame').textContent =
      `${h.frame_ms.toFixed(1)} ms, ${h.width}×${h.height}${h.preview ? ' (preview)' : ''}` +
      `${h.reduced > 1 ? ` (render budget: 1/${h.reduced})` : ''}, ${fps.toFixed(1)} fps`;
    $('o-spr').textContent = h.samples_per_ray.toFixed(1);
    $('o-skipped').textContent = (100 * h.skipped).toFixed(1) + ' %';
    if (h.tf_changed) {
      lastTfReport = h;
      $('o-tf').textContent =
        `${h.tf_update_ms.toFixed(2)} ms update, ${h.tf_latency_ms.toFixed(2)} ms from message`;
      $('o-tf').dataset.ms = String(h.tf_update_ms);
    }
    $('o-accel').textContent = h.accel +
      (h.accel_build_ms > 0 ? ` (built in ${h.accel_build_ms.toFixed(0)} ms)` : '') +
      (lastTfReport ? '' : '');
  }

  // ---- camera: orbit, pan, zoom (mouse and touch through pointer events) -------------------
  const pointers = new Map();
  let pinch = null;

  view.addEventListener('contextmenu', (e) => e.preventDefault());
  view.addEventListener('pointerdown', (e) => {
    view.setPointerCapture(e.pointerId);
    pointers.set(e.pointerId, { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey });
    interacting = true;
    view.classList.add('dragging');
    if (pointers.size === 2) pinch = pinchState();
  });
  view.addEventListener('pointermove', (e) => {
    const p = pointers.get(e.pointerId);
    if (!p) return;
    const dx = e.clientX - p.x, dy = e.clientY - p.y;
    p.x = e.clientX;
    p.y = e.clientY;
    const cam = state.camera;
    if (pointers.size >= 2) {
      const now = pinchState();
      if (pinch && pinch.dist > 0) cam.zoom = clamp(cam.zoom * now.dist / pinch.dist, 0.1, 40);
      panBy(now.cx - pinch.cx, now.cy - pinch.cy);
      pinch = now;
    } else if (p.pan) {
      panBy(dx, dy);
    } else {
      $('view-name').value = '';
      if (cam.view) {
        // Leave the named view for free angles, starting where it is (free elevation stops at
        // +-89.9 in the protocol; the page keeps to +-89).
        const [az, el] = kViews[cam.view];
        delete cam.view;
        cam.azimuth = az;
        cam.elevation = clamp(el, -89, 89);
      }
      cam.azimuth = (cam.azimuth - dx * 0.4) % 360;
      cam.elevation = clamp(cam.elevation + dy * 0.4, -89, 89);
    }
    request(true);
  });
  const release = (e) => {
    pointers.delete(e.pointerId);
    pinch = pointers.size === 2 ? pinchState() : null;
    if (pointers.size === 0) {
      interacting = false;
      view.classList.remove('dragging');
      request(false);
    }
  };
  view.addEventListener('pointerup', release);
  view.addEventListener('pointercancel', release);
  view.addEventListener('wheel', (e) => {
    e.preventDefault();
    state.camera.zoom = clamp(state.camera.zoom * Math.exp(-e.deltaY * 0.0015), 0.1, 40);
    request(true);
  }, { passive: false });
  view.addEventListener('dblclick', () => {
    state.camera = { azimuth: 30, elevation: 15, zoom: 1, pan: [0, 0] };
    request(false);
  });

  function pinchState() {
    const [a, b] = [...pointers.values()];
    return { dist: Math.hypot(a.x - b.x, a.y - b.y), cx: (a.x + b.x) / 2, cy: (a.y + b.y) / 2 };
  }
  // Pan in bounding radii: a drag across the view's height moves about two radii / zoom.
  function panBy(dx, dy) {
    const k = 2 / (Math.max(1, view.clientHeight) * state.camera.zoom);
    state.camera.pan = [clamp(state.camera.pan[0] - dx * k, -50, 50),
                        clamp(state.camera.pan[1] + dy * k, -50, 50)];
  }
  window.addEventListener('resize', () => { request(false); if (hello) showShotSize(); });

  // ---- controls -----------------------------------------------------------------------------
  function fillSelect(sel, names, value) {
    sel.innerHTML = '';
    for (const n of names) {
      const o = document.createElement('option');
      o.value = o.textContent = n;
      sel.appendChild(o);
    }
    sel.value = names.includes(value) ? value : names[0];
  }
  // What combines with what is the server's capabilities table (hello.capabilities, from
  // lacuna::capabilities()): per renderer the accels it takes and its features; the segments
  // toggle is a renderer of its own, drawn with caps.segments.renderer. The page only follows it.
  const caps = () => hello.capabilities;
  const current = () => (state.segments ? caps().segments : caps()[state.renderer]);
  const setRenderer = (r) => { state.renderer = r; $('renderer').value = r; };
  const noSegments = () => { state.segments = false; $('segments').checked = false; };
  const noShading = () => { state.shading = false; $('shading').checked = false; };
  const noClipping = () => {
    state.clip = false; state.clipPlanes = []; $('clip-planes').value = ''; $('clip').checked = false;
  };
  // Switches off what the current renderer cannot take: an accel becomes its first one that skips
  // (else its first), shading and clipping go off.
  function fitToRenderer() {
    const c = current();
    if (!c.accels.includes(state.accel)) {
      state.accel = c.accels.find((a) => a !== 'none') || c.accels[0];
      $('accel').value = state.accel;
    }
    if (!c.features.includes('shading')) noShading();
    if (!c.features.includes('clip_planes')) noClipping();
  }
  // A choice the current renderer cannot take moves to the first one that can (segments off).
  function rendererFor(ok) {
    if (ok(current())) return;
    if (state.segments) noSegments();
    if (ok(caps()[state.renderer])) return;
    const r = hello.renderers.find((n) => ok(caps()[n]));
    if (r) setRenderer(r);
  }
  $('renderer').addEventListener('change', (e) => {
    state.renderer = e.target.value;
    if (state.segments && caps().segments.renderer !== state.renderer) noSegments();
    fitToRenderer();
    request(false);
  });
  $('accel').addEventListener('change', (e) => {
    state.accel = e.target.value;
    rendererFor((c) => c.accels.includes(state.accel));
    request(false);
  });
  $('ert').addEventListener('change', (e) => { state.ert = e.target.checked; request(false); });
  $('segments').addEventListener('change', (e) => {
    state.segments = e.target.checked;
    if (state.segments) {
      setRenderer(caps().segments.renderer);
      fitToRenderer();
    }
    request(false);
  });
  $('hide').addEventListener('change', (e) => { state.hide = e.target.value.trim(); request(false); });
  $('shading').addEventListener('change', (e) => {
    state.shading = e.target.checked;
    if (state.shading) rendererFor((c) => c.features.includes('shading'));
    request(false);
  });
  // Named anatomical views: the page sends the name ("camera": {"view": "left", ...}) and the
  // server takes the angles from the table `lacuna render --view` uses (lacuna/views.h), so a
  // view here is the CLI's view bit for bit. These angles only seed a drag away from the view.
  $('view-name').addEventListener('change', (e) => {
    if (!kViews[e.target.value]) return;
    state.camera = { view: e.target.value, zoom: state.camera.zoom, pan: [0, 0] };
    request(false);
  });
  // Clip planes in world (patient RAS) mm, "NX,NY,NZ,D; ..." as lacuna render --clip: each keeps
  // dot(n, p) >= D. Anything else marks the field invalid and sends no planes.
  $('clip-planes').addEventListener('change', (e) => {
    const text = e.target.value.trim();
    const planes = text === '' ? [] : text.split(';').map((t) => t.split(',').map(Number));
    const ok = planes.every((p) => p.length === 4 && p.every(Number.isFinite) &&
                                   (p[0] !== 0 || p[1] !== 0 || p[2] !== 0));
    e.target.classList.toggle('invalid', !ok);
    state.clipPlanes = ok ? planes : [];
    if (ok && planes.length) rendererFor((c) => c.features.includes('clip_planes'));
    request(false);
  });
  $('clip').addEventListener('change', (e) => {
    state.clip = e.target.checked;
    if (state.clip) rendererFor((c) => c.features.includes('clip_planes'));
    request(false);
  });
  $('step').addEventListener('input', (e) => {
    state.step = Number(e.target.value);
    $('step-value').textContent = e.target.value;
    request(true);
  });
  $('preset').addEventListener('change', (e) => {
    if (!e.target.value) return;
    setTf(hello.presets[e.target.value]);
    request(false);
  });
  $('logscale').addEventListener('change', drawTf);

  // ---- transfer function editor -------------------------------------------------------------
  // Takes a TF from the server (a preset or the initial one) into the editor's normalized form.
  // A value-domain TF (a Slicer file, a value preset) becomes normalized over its range, else the
  // volume's visualization range: the range its LUT is discretised over. Points outside it are
  // cut at its ends (the piecewise-linear function evaluated there), so the TF stays the same
  // over the range instead of clamping points onto its ends.
  function setTf(tf) {
    const copy = JSON.parse(JSON.stringify(tf));
    if (copy.domain === 'value') {
      const [lo, hi] = copy.range || hello.volume.vis_range;
      const norm = (x) => clamp((x - lo) / (hi - lo), 0, 1);
      copy.color = clipPoints(copy.color, lo, hi);
      copy.opacity = clipPoints(copy.opacity, lo, hi);
      copy.color.forEach((p) => { p[0] = norm(p[0]); });
      copy.opacity.forEach((p) => { p[0] = norm(p[0]); });
      copy.domain = 'normalized';
      copy.range = [lo, hi];
    }
    delete copy.description;
    state.tf = copy;
    selectedStop = -1;
    drawTf();
  }
  // Points [x, ...values] sorted by x (two may share an x: a step, the second wins at x) cut to
  // [lo, hi]: unchanged when all lie inside, else the inside points between the function's
  // values at lo (from the right) and at hi (from the left, and from the right when a step sits
  // on hi).
  function clipPoints(pts, lo, hi) {
    if (pts.every((p) => p[0] >= lo && p[0] <= hi)) return pts;
    const lerp = (a, b, x) => a.slice(1).map((v, k) => v + (x - a[0]) / (b[0] - a[0]) * (b[k + 1] - v));
    // The value at x from the right (right = true) or from the left.
    const at = (x, right) => {
      if (right ? x < pts[0][0] : x <= pts[0][0]) return pts[0].slice(1);
      const last = pts[pts.length - 1];
      if (right ? x >= last[0] : x > last[0]) return last.slice(1);
      let i = 0;
      while (right ? pts[i + 1][0] <= x : pts[i + 1][0] < x) i++;
      return lerp(pts[i], pts[i + 1], x);
    };
    const out = [[lo, ...at(lo, true)], ...pts.filter((p) => p[0] > lo && p[0] < hi), [hi, ...at(hi, false)]];
    const right = at(hi, true);
    if (right.some((v, k) => v !== out[out.length - 1][k + 1])) out.push([hi, ...right]);
    return out;
  }
  function edited() {
    state.tf.name = 'edited';
    $('preset').value = '';
  }

  const PAD = 6;  // pixels around the plot, so end points stay grabbable
  const plotW = () => tfCanvas.width - 2 * PAD, plotH = () => tfCanvas.height - 2 * PAD;
  const toX = (x) => PAD + x * plotW();
  const toY = (a) => PAD + (1 - a) * plotH();
  const fromX = (px) => clamp((px - PAD) / plotW(), 0, 1);
  const fromY = (py) => clamp(1 - (py - PAD) / plotH(), 0, 1);

  // Canvas coordinates of opacity point i (tests drive the editor through these).
  function opacityPointClient(i) {
    const r = tfCanvas.getBoundingClientRect();
    const p = state.tf.opacity[i];
    return { x: r.left + toX(p[0]) * r.width / tfCanvas.width, y: r.top + toY(p[1]) * r.height / tfCanvas.height };
  }

  function colorAt(x) {
    const c = state.tf.color;
    if (x <= c[0][0]) return c[0].slice(1);
    for (let i = 1; i < c.length; i++) {
      if (x <= c[i][0]) {
        const t = c[i][0] > c[i - 1][0] ? (x - c[i - 1][0]) / (c[i][0] - c[i - 1][0]) : 1;
        return [1, 2, 3].map((k) => c[i - 1][k] + t * (c[i][k] - c[i - 1][k]));
      }
    }
    return c[c.length - 1].slice(1);
  }
  const css = (rgb) => `rgb(${rgb.map((v) => Math.round(255 * v)).join(',')})`;

  function drawTf() {
    if (!state.tf || !hello) return;
    const g = tfCanvas.getContext('2d');
    const W = tfCanvas.width, H = tfCanvas.height;
    g.clearRect(0, 0, W, H);
    // Histogram of the volume over the visualization range.
    const hist = hello.histogram;
    const log = $('logscale').checked;
    const f = (v) => (log ? Math.log1p(v) : v);
    const peak = Math.max(1, ...hist.map(f));
    g.fillStyle = '#3a3f48';
    const bw = plotW() / hist.length;
    hist.forEach((v, i) => {
      const h = (f(v) / peak) * plotH();
      g.fillRect(PAD + i * bw, PAD + plotH() - h, Math.max(1, bw), h);
    });
    // Opacity curve, filled with the TF's colour.
    const op = state.tf.opacity;
    const grad = g.createLinearGradient(PAD, 0, PAD + plotW(), 0);
    for (let k = 0; k <= 16; k++) grad.addColorStop(k / 16, css(colorAt(k / 16)));
    g.beginPath();
    g.moveTo(toX(0), toY(0));
    g.lineTo(toX(0), toY(op[0][1]));
    for (const p of op) g.lineTo(toX(p[0]), toY(p[1]));
    g.lineTo(toX(1), toY(op[op.length - 1][1]));
    g.lineTo(toX(1), toY(0));
    g.closePath();
    g.globalAlpha = 0.45;
    g.fillStyle = grad;
    g.fill();
    g.globalAlpha = 1;
    g.strokeStyle = '#eee';
    g.lineWidth = 1.5;
    g.beginPath();
    op.forEach((p, i) => (i ? g.lineTo(toX(p[0]), toY(p[1])) : g.moveTo(toX(p[0]), toY(p[1]))));
    g.stroke();
    op.forEach((p, i) => {
      g.beginPath();
      g.arc(toX(p[0]), toY(p[1]), 4.5, 0, 2 * Math.PI);
      g.fillStyle = i === dragPoint ? '#fc6' : '#fff';
      g.fill();
      g.strokeStyle = '#000';
      g.stroke();
    });
    drawColors();
  }

  function drawColors() {
    const g = colorCanvas.getContext('2d');
    const W = colorCanvas.width, H = colorCanvas.height;
    g.clearRect(0, 0, W, H);
    for (let px = 0; px < plotW(); px++) {
      g.fillStyle = css(colorAt(px / (plotW() - 1)));
      g.fillRect(PAD + px, 0, 1, H - 9);
    }
    state.tf.color.forEach((c, i) => {
      const x = toX(c[0]);
      g.beginPath();
      g.moveTo(x, H - 10);
      g.lineTo(x - 5, H - 1);
      g.lineTo(x + 5, H - 1);
      g.closePath();
      g.fillStyle = css(c.slice(1));
      g.fill();
      g.strokeStyle = i === selectedStop ? '#fc6' : '#aaa';
      g.lineWidth = i === selectedStop ? 2 : 1;
      g.stroke();
    });
  }

  const canvasPos = (canvas, e) => {
    const r = canvas.getBoundingClientRect();
    return { x: (e.clientX - r.left) * canvas.width / r.width, y: (e.clientY - r.top) * canvas.height / r.height };
  };
  function nearestPoint(points, pos, useY) {
    let best = -1, bestD = 9;  // pixels
    points.forEach((p, i) => {
      const d = useY ? Math.hypot(toX(p[0]) - pos.x, toY(p[1]) - pos.y) : Math.abs(toX(p[0]) - pos.x);
      if (d <= bestD) { best = i; bestD = d; }
    });
    return best;
  }

  // Opacity points: drag to move (x stays between the neighbours), double-click to add or remove.
  let dragPoint = -1;
  tfCanvas.addEventListener('pointerdown', (e) => {
    if (!state.tf) return;
    const i = nearestPoint(state.tf.opacity, canvasPos(tfCanvas, e), true);
    if (i < 0) return;
    dragPoint = i;
    interacting = true;
    tfCanvas.setPointerCapture(e.pointerId);
    drawTf();
  });
  tfCanvas.addEventListener('pointermove', (e) => {
    if (dragPoint < 0) return;
    const pos = canvasPos(tfCanvas, e), op = state.tf.opacity, i = dragPoint;
    const lo = i > 0 ? op[i - 1][0] : 0, hi = i < op.length - 1 ? op[i + 1][0] : 1;
    op[i] = [round4(clamp(fromX(pos.x), lo, hi)), round4(fromY(pos.y))];
    edited();
    drawTf();
    request(true);
  });
  const endDrag = () => {
    if (dragPoint < 0) return;
    dragPoint = -1;
    interacting = false;
    drawTf();
    request(false);
  };
  tfCanvas.addEventListener('pointerup', endDrag);
  tfCanvas.addEventListener('pointercancel', endDrag);
  tfCanvas.addEventListener('dblclick', (e) => {
    const pos = canvasPos(tfCanvas, e), op = state.tf.opacity;
    const i = nearestPoint(op, pos, true);
    if (i >= 0) {
      if (op.length > 1) op.splice(i, 1);
    } else {
      const x = round4(fromX(pos.x));
      if (op.filter((p) => p[0] === x).length >= 2) return;  // at most two points share an x
      let at = op.findIndex((p) => p[0] > x);
      if (at < 0) at = op.length;
      op.splice(at, 0, [x, round4(fromY(pos.y))]);
    }
    edited();
    drawTf();
    request(false);
  });

  // Colour stops: click selects (the colour input edits it), drag moves, double-click adds.
  let dragStop = -1;
  colorCanvas.addEventListener('pointerdown', (e) => {
    const i = nearestPoint(state.tf.color, canvasPos(colorCanvas, e), false);
    if (i < 0) return;
    selectedStop = dragStop = i;
    const c = state.tf.color[i];
    $('stop-color').value = '#' + c.slice(1).map((v) => Math.round(255 * v).toString(16).padStart(2, '0')).join('');
    colorCanvas.setPointerCapture(e.pointerId);
    interacting = true;
    drawColors();
  });
  colorCanvas.addEventListener('pointermove', (e) => {
    if (dragStop < 0) return;
    const c = state.tf.color, i = dragStop;
    const lo = i > 0 ? c[i - 1][0] : 0, hi = i < c.length - 1 ? c[i + 1][0] : 1;
    c[i][0] = round4(clamp(fromX(canvasPos(colorCanvas, e).x), lo, hi));
    edited();
    drawTf();
    request(true);
  });
  const endStop = () => {
    if (dragStop < 0) return;
    dragStop = -1;
    interacting = false;
    request(false);
  };
  colorCanvas.addEventListener('pointerup', endStop);
  colorCanvas.addEventListener('pointercancel', endStop);
  colorCanvas.addEventListener('dblclick', (e) => {
    const x = round4(fromX(canvasPos(colorCanvas, e).x)), c = state.tf.color;
    if (nearestPoint(c, canvasPos(colorCanvas, e), false) >= 0) return;
    let at = c.findIndex((p) => p[0] > x);
    if (at < 0) at = c.length;
    c.splice(at, 0, [x, ...colorAt(x).map(round4)]);
    selectedStop = at;
    edited();
    drawTf();
    request(false);
  });
  $('stop-color').addEventListener('input', (e) => {
    if (selectedStop < 0) return;
    const v = e.target.value;
    const rgb = [1, 3, 5].map((k) => round4(parseInt(v.slice(k, k + 2), 16) / 255));
    state.tf.color[selectedStop] = [state.tf.color[selectedStop][0], ...rgb];
    edited();
    drawTf();
    request(true);
  });
  $('stop-remove').addEventListener('click', () => {
    if (selectedStop < 0 || state.tf.color.length <= 1) return;
    state.tf.color.splice(selectedStop, 1);
    selectedStop = -1;
    edited();
    drawTf();
    request(false);
  });

  // ---- slice panes (axial, coronal, sagittal) ------------------------------------------------
  const kPlanes = ['axial', 'coronal', 'sagittal'];
  // Each plane's normal (lacuna/mpr.h): a pane's picture depends on the crosshair only through
  // the point's coordinate along it, so moving the point within a plane leaves that pane as it is.
  const kNormals = { axial: [0, 0, 1], coronal: [0, 1, 0], sagittal: [1, 0, 0] };
  // 3D Slicer's Volumes module presets, [window, level] in the volume's units (HU for CT);
  // 'vis' and 'full' come from the volume (its visualization and data ranges).
  const kWindowLevel = { 'ct-brain': [100, 50], 'ct-abdomen': [350, 40], 'ct-bone': [1000, 400],
                         'ct-lung': [1400, -500] };
  const kCrosshair = '#ffcc00';
  const panes = {};
  for (const plane of kPlanes) {
    const el = $('pane-' + plane);
    panes[plane] = { plane, el, canvas: el.querySelector('canvas'), inFlight: null, dirty: false,
                     sentKey: null, sentPoints: new Map(), header: null, point: null, bitmap: null,
                     fit: null, count: 0, arrived: 0, shown: 0, drag: null };
  }
  let probeInFlight = null, probeDirty = false, lastProbe = null;
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const slicesServed = () => hello && (hello.messages || []).includes('slice');
  const hasLabels = () => hello && hello.labels > 0;
  const fmt = (x) => (Number.isInteger(x) ? String(x) : String(+x.toPrecision(5)));

  function startSlices(msg) {
    for (const pane of Object.values(panes)) pane.el.hidden = !slicesServed();
    if (!slicesServed()) return;
    const b = msg.volume.world_bounds;
    state.point = b ? [0, 1, 2].map((a) => (b.lo[a] + b.hi[a]) / 2) : [0, 0, 0];
    fillSelect($('slice-interp'), msg.slice_views.interpolations, state.interpolation);
    state.interpolation = $('slice-interp').value;
    $('overlay-row').hidden = !hasLabels();
    applyWindowLevel(state.wlPreset);
    requestSlices();
    requestProbe();
  }

  // What a pane's picture depends on; a pane is fetched again only when this changes.
  function sliceKey(pane) {
    return JSON.stringify([dot(state.point, kNormals[pane.plane]), state.window, state.level,
                           state.interpolation, hasLabels() ? state.overlayOpacity : 0,
                           state.volumeFrame]);
  }
  function requestSlices() {
    for (const pane of Object.values(panes)) {
      if (sliceKey(pane) !== pane.sentKey) pane.dirty = true;
      flushSlice(pane);
    }
  }
  function flushSlice(pane) {
    if (!pane.dirty || pane.inFlight !== null || !ws || ws.readyState !== WebSocket.OPEN ||
        !slicesServed()) return;
    const id = nextId++;
    const msg = { type: 'slice', id, plane: pane.plane, point: state.point, window: state.window,
                  level: state.level, interpolation: state.interpolation };
    if (hasLabels() && state.overlayOpacity > 0) msg.overlay_opacity = state.overlayOpacity;
    ws.send(JSON.stringify(msg));
    pane.inFlight = id;
    pane.sentKey = sliceKey(pane);
    pane.sentPoints.set(id, state.point.slice());
    pane.dirty = false;
  }

  // A slice arrived: decode it off the main path, show it unless a newer one is shown already.
  function onSlice(header, jpeg) {
    const pane = panes[header.plane];
    if (!pane) return;
    if (header.id === pane.inFlight) pane.inFlight = null;
    const point = pane.sentPoints.get(header.id);
    pane.sentPoints.delete(header.id);
    const seq = ++pane.arrived;
    createImageBitmap(new Blob([jpeg], { type: 'image/jpeg' })).then((bitmap) => {
      if (seq < pane.shown) { bitmap.close(); return; }
      if (pane.bitmap) pane.bitmap.close();
      pane.shown = seq;
      pane.bitmap = bitmap;
      pane.header = header;
      pane.point = point;
      pane.count += 1;
      drawPane(pane);
    }, (e) => setStatus(`${header.plane} slice: ${e}`));
    flushSlice(pane);
  }

  // The slice letterboxed in its pane (its pixels are square: pixel_mm on both axes); pixel
  // (c, r)'s centre is at canvas (ox + (c + 0.5) s, oy + (r + 0.5) s).
  function drawPane(pane) {
    const c = pane.canvas, dpr = Math.min(window.devicePixelRatio || 1, 2);
    const W = Math.max(1, Math.round(c.clientWidth * dpr)), H = Math.max(1, Math.round(c.clientHeight * dpr));
    if (c.width !== W || c.height !== H) { c.width = W; c.height = H; }
    const g = c.getContext('2d');
    g.fillStyle = '#000';
    g.fillRect(0, 0, W, H);
    const h = pane.header;
    if (!pane.bitmap || !h) return;
    const s = Math.min(W / h.width, H / h.height);
    const ox = Math.round((W - s * h.width) / 2), oy = Math.round((H - s * h.height) / 2);
    pane.fit = { s, ox, oy };
    g.imageSmoothingEnabled = h.interpolation !== 'nearest';
    g.drawImage(pane.bitmap, ox, oy, s * h.width, s * h.height);
    // The crosshair: a 1-pixel line on pixel centres (so its colour is exact).
    const [x, y] = worldToCanvas(pane, state.point).map((t) => Math.floor(t) + 0.5);
    g.strokeStyle = kCrosshair;
    g.lineWidth = 1;
    g.beginPath();
    g.moveTo(x, oy);
    g.lineTo(x, oy + s * h.height);
    g.moveTo(ox, y);
    g.lineTo(ox + s * h.width, y);
    g.stroke();
  }
  const drawPanes = () => Object.values(panes).forEach(drawPane);

  // World (RAS mm) <-> canvas pixels through the slice header's map origin + c u + r v.
  function worldToCanvas(pane, p) {
    const h = pane.header, f = pane.fit, d = [0, 1, 2].map((a) => p[a] - h.origin[a]);
    const col = dot(d, h.u) / dot(h.u, h.u), row = dot(d, h.v) / dot(h.v, h.v);
    return [f.ox + (col + 0.5) * f.s, f.oy + (row + 0.5) * f.s];
  }
  // Clamped to the slice's pixels (the volume's box projected on the plane), and kept on the
  // pane's own plane (the crosshair's coordinate along the normal does not move).
  function canvasToWorld(pane, x, y) {
    const h = pane.header, f = pane.fit;
    const col = clamp((x - f.ox) / f.s - 0.5, 0, h.width - 1), row = clamp((y - f.oy) / f.s - 0.5, 0, h.height - 1);
    const w = [0, 1, 2].map((a) => h.origin[a] + col * h.u[a] + row * h.v[a]);
    const n = kNormals[pane.plane], a = n.indexOf(1);
    w[a] = state.point[a];
    return w;
  }
  function clientToCanvas(pane, e) {
    const r = pane.canvas.getBoundingClientRect();
    return [(e.clientX - r.left) * pane.canvas.width / r.width, (e.clientY - r.top) * pane.canvas.height / r.height];
  }

  function moveCrosshair(pane, e) {
    state.point = canvasToWorld(pane, ...clientToCanvas(pane, e)).map((t) => Math.round(t * 1e4) / 1e4);
    drawPanes();
    requestSlices();
    requestProbe();
  }

  // Window/level: the preset menu, or right/shift-drag in a slice (horizontal = window, vertical =
  // level, as in 3D Slicer; right widens the window, down raises the level), 1/400 of the data
  // range per pixel.
  function applyWindowLevel(name) {
    const v = hello.volume;
    let wl = kWindowLevel[name];
    if (name === 'vis' || name === 'full') {
      const [lo, hi] = name === 'vis' ? v.vis_range : v.data_range;
      wl = [hi > lo ? hi - lo : 1, (lo + hi) / 2];
    }
    if (!wl) return;
    [state.window, state.level] = wl;
    state.wlPreset = name;
    $('wl-preset').value = name;
    showWindowLevel();
  }
  function showWindowLevel() {
    $('wl-text').textContent = `window ${fmt(state.window)} · level ${fmt(state.level)}`;
  }
  function dataRange() {
    const [lo, hi] = hello.volume.data_range;
    return hi > lo ? hi - lo : 1;
  }

  for (const pane of Object.values(panes)) {
    const el = pane.el;
    el.addEventListener('contextmenu', (e) => e.preventDefault());
    el.addEventListener('pointerdown', (e) => {
      if (!pane.header || !pane.fit) return;
      el.setPointerCapture(e.pointerId);
      const wl = e.button === 2 || e.shiftKey;
      pane.drag = { wl, x: e.clientX, y: e.clientY, window: state.window, level: state.level };
      if (!wl) moveCrosshair(pane, e);
    });
    el.addEventListener('pointermove', (e) => {
      const d = pane.drag;
      if (!d) return;
      if (!d.wl) return moveCrosshair(pane, e);
      const k = dataRange() / 400;
      state.window = clamp(d.window + (e.clientX - d.x) * k, dataRange() * 1e-4, 1e12);
      state.level = clamp(d.level + (e.clientY - d.y) * k, -1e12, 1e12);
      state.wlPreset = 'custom';
      $('wl-preset').value = 'custom';
      showWindowLevel();
      requestSlices();
    });
    const end = (e) => { if (pane.drag) { pane.drag = null; el.releasePointerCapture(e.pointerId); } };
    el.addEventListener('pointerup', end);
    el.addEventListener('pointercancel', end);
    new ResizeObserver(() => drawPane(pane)).observe(el);
  }
  $('wl-preset').addEventListener('change', (e) => {
    if (e.target.value === 'custom') return;
    applyWindowLevel(e.target.value);
    requestSlices();
  });
  $('slice-interp').addEventListener('change', (e) => {
    state.interpolation = e.target.value;
    requestSlices();
    requestProbe();
  });
  $('overlay-opacity').addEventListener('input', (e) => {
    state.overlayOpacity = Number(e.target.value);
    $('overlay-value').textContent = e.target.value;
    requestSlices();
  });

  // ---- probe: the value under the crosshair ---------------------------------------------------
  function requestProbe() {
    probeDirty = true;
    flushProbe();
  }
  function flushProbe() {
    if (!probeDirty || probeInFlight !== null || !ws || ws.readyState !== WebSocket.OPEN ||
        !slicesServed()) return;
    const id = nextId++;
    ws.send(JSON.stringify({ type: 'probe', id, point: state.point, interpolation: state.interpolation }));
    probeInFlight = id;
    probeDirty = false;
  }
  function onProbe(msg) {
    if (msg.id === probeInFlight) probeInFlight = null;
    lastProbe = msg;
    const lines = [`RAS ${msg.point.map((x) => x.toFixed(1)).join(', ')} mm`];
    if (msg.inside) {
      lines.push(`voxel [${msg.voxel.join(', ')}] = ${fmt(msg.voxel_value)}`);
      lines.push(`value ${fmt(msg.value)} (${state.interpolation})`);
    } else {
      lines.push('outside the volume');
    }
    if (hasLabels()) {
      lines.push(msg.label === null ? 'label –' : `label ${msg.label}${msg.label_name ? ' ' + msg.label_name : ''}`);
    }
    $('probe').textContent = lines.join('\n');
    flushProbe();
  }

  function clamp(v, lo, hi) { return Math.min(hi, Math.max(lo, v)); }
  function round4(v) { return Math.round(v * 10000) / 10000; }

  // A small handle for scripts and tests (tests/e2e/viewer.e2e.mjs).
  // Slice panes: slices() gives each pane's shown slice (its header, the crosshair point it was
  // fetched through, how many were shown, its place in the canvas, and whether the newest state
  // is shown: nothing in flight, dirty or decoding); sliceClient(plane, c, r) is the page position of pixel
  // (c, r)'s centre and crosshairCanvas(plane) the crosshair in canvas pixels; probe() the last
  // probe answer.
  const slices = () => Object.fromEntries(kPlanes.map((p) => [p, {
    header: panes[p].header, point: panes[p].point, count: panes[p].count, fit: panes[p].fit,
    settled: panes[p].inFlight === null && !panes[p].dirty && panes[p].shown === panes[p].arrived }]));
  function sliceClient(plane, c, r) {
    const pane = panes[plane], f = pane.fit, rect = pane.canvas.getBoundingClientRect();
    const k = rect.width / pane.canvas.width;
    return { x: rect.left + (f.ox + (c + 0.5) * f.s) * k, y: rect.top + (f.oy + (r + 0.5) * f.s) * k };
  }
  const crosshairCanvas = (plane) => worldToCanvas(panes[plane], state.point).map(Math.floor);
  window.lacunaViewer = { state, opacityPointClient, frames: () => frames, frameLog, hello: () => hello,
                          slices, sliceClient, crosshairCanvas, probe: () => lastProbe };
  connect();
})();
