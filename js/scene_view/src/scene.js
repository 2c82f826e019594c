// robot_lab.scene_view's browser side: a three.js scene fed by the kernel over the widget's
// channel (anywidget). The kernel resolves every TF frame's pose in the fixed frame and sends
// only what changed; this side places displays under their frames and draws a frame only
// when something changed or the camera moved. Nothing is fetched: meshes and textures come
// as binary buffers, so the view works on JupyterHub and Binder with no route or port.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { DISPLAYS } from './displays.js';
import { MeshStore } from './meshes.js';

const CSS = `
.rl-scene { max-width: 960px; font: 12px var(--jp-ui-font-family, sans-serif); }
.rl-scene canvas { display: block; width: 100%; outline: none; touch-action: none; }
.rl-scene .rl-bar { display: flex; gap: 10px; align-items: center; padding: 2px 0 4px; }
.rl-scene select { font: inherit; max-width: 18em; }
.rl-scene details { max-height: 9em; overflow: auto; }
.rl-scene details label { margin-right: 10px; white-space: nowrap; display: inline-block; }
.rl-scene .rl-status { color: #666; min-height: 1.4em; white-space: pre-wrap; }
.rl-scene .rl-status .rl-warn { color: #b35900; }
`;

function addStyle() {
  if (document.getElementById('robot-lab-scene-style')) return;
  const style = document.createElement('style');
  style.id = 'robot-lab-scene-style';
  style.textContent = CSS;
  document.head.appendChild(style);
}

function el(tag, props = {}, ...children) {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
}

// A buffer from the widget channel as bytes (ipywidgets gives DataViews or ArrayBuffers).
function bytes(buffer) {
  if (buffer instanceof ArrayBuffer) return new Uint8Array(buffer);
  return new Uint8Array(buffer.buffer, buffer.byteOffset, buffer.byteLength);
}

let software = null;
function softwareGL() {
  if (software === null) {
    const probe = document.createElement('canvas').getContext('webgl2')
      || document.createElement('canvas').getContext('webgl');
    const info = probe && probe.getExtension('WEBGL_debug_renderer_info');
    const name = info ? String(probe.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
    software = /swiftshader|llvmpipe|software/i.test(name);
    probe?.getExtension('WEBGL_lose_context')?.loseContext();
  }
  return software;
}

function render({ model, el: host }) {
  addStyle();
  const height = model.get('height') || 480;
  const fixedSelect = el('select', { title: 'the fixed frame every pose is shown in' });
  const framesBox = el('details', {}, el('summary', { textContent: 'TF frames' }));
  const bar = el('div', { className: 'rl-bar' },
    el('label', { textContent: 'Fixed frame ' }, fixedSelect));
  const canvas = el('canvas', { tabIndex: 0 });
  const status = el('div', { className: 'rl-status' });
  const root = el('div', { className: 'rl-scene' }, bar, canvas, framesBox, status);
  host.appendChild(root);

  let renderer;
  try {
    // Multisampling costs a software renderer (SwiftShader, llvmpipe: a hub's browser on
    // a machine without a GPU) about half its frame rate; a GPU does it for free.
    renderer = new THREE.WebGLRenderer({ canvas, antialias: !softwareGL() });
  } catch (err) {
    status.textContent = 'This browser has no WebGL, so the 3D view cannot draw: ' + err;
    root.dataset.webgl = 'none';
    return () => {};
  }
  root.dataset.webgl = (renderer.capabilities.isWebGL2 ? 'webgl2' : 'webgl')
    + (softwareGL() ? ' software' : '');
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x303030);  // RViz's background
  const camera = new THREE.PerspectiveCamera(50, 2, 0.01, 500);
  camera.up.set(0, 0, 1);  // ROS: z up
  camera.position.set(1.8, 1.4, 1.2);
  scene.add(camera);
  scene.add(new THREE.AmbientLight(0xffffff, 1.2));
  const light = new THREE.DirectionalLight(0xffffff, 1.8);
  light.position.set(0.5, 1, 2);
  camera.add(light);  // a light at the eye, as RViz's
  const controls = new OrbitControls(camera, canvas);
  controls.target.set(0, 0, 0.3);
  controls.screenSpacePanning = true;
  controls.update();

  // Frames: the kernel's poses in the fixed frame. A frame with no pose is null.
  const ctx = {
    scene, camera, canvas, root, model,
    poses: new Map(), // name -> THREE.Matrix4 | null
    parents: new Map(), // child -> parent (the TF tree, for the TF display's arrows)
    fixed: '',
    hidden: new Set(model.get('hidden_frames') || []),
    meshes: new MeshStore(),
    notes: new Map(), // display id -> its browser-side problems (mesh errors), for the status
    wake: () => wake(),
  };
  const displays = new Map();  // id -> display object
  root.rlPoses = ctx.poses;  // what the page shows, for tests and the curious (no DOM writes)

  // Draw only when something changed, and only while the view is on screen: a notebook
  // scrolled past a live view costs the page nothing (it draws again when it comes back).
  let dirty = true, handle = 0, frames = 0, stopped = false, lastStatus = '', seen = true;
  const wake = () => {
    dirty = true;
    if (!handle && !stopped && seen) handle = requestAnimationFrame(draw);
  };
  // The kernel sends nothing while every view of the widget is out of sight.
  const viewId = Math.random().toString(36).slice(2);
  const watch = new IntersectionObserver((entries) => {
    const now = entries[entries.length - 1].isIntersecting;
    if (now !== seen) model.send({ kind: 'seen', view: viewId, value: now });
    seen = now;
    if (seen && dirty) wake();
  });
  watch.observe(root);
  const size = () => {
    const width = Math.max(200, Math.min(root.clientWidth || 800, 960));
    const cur = renderer.getSize(new THREE.Vector2());
    if (cur.x !== width || cur.y !== height) {
      renderer.setSize(width, height, false);
      canvas.style.height = height + 'px';
      camera.aspect = width / height;
      camera.updateProjectionMatrix();
    }
  };
  const showStatus = () => {
    const lines = [...(model.get('status') || [])];
    for (const notes of ctx.notes.values()) lines.push(...notes);
    const text = lines.join('\n');
    if (text === lastStatus) return;
    lastStatus = text;
    status.replaceChildren(...lines.map((line) => el('div', {
      className: /^(No transform|Error|Warning|[^:]*: (no|cannot|missing))/i.test(line)
        ? 'rl-warn' : '', textContent: line })));
  };
  const draw = () => {
    handle = 0;
    if (stopped || !root.isConnected || !dirty || !seen) return;
    dirty = false;
    size();
    camera.updateMatrixWorld();  // moved since the last frame: beforeRender projects with it
    for (const display of displays.values()) display.beforeRender?.();
    renderer.render(scene, camera);
    frames += 1;
    root.dataset.frames = String(frames);
    root.dataset.drawnPoses = root.dataset.poses || '0';  // the pose updates this frame shows
    showStatus();
  };
  controls.addEventListener('change', wake);
  const resize = new ResizeObserver(wake);
  resize.observe(root);

  const setPoses = (poses) => {
    for (const [name, p] of Object.entries(poses)) {
      if (p === null) { ctx.poses.set(name, null); continue; }
      const m = ctx.poses.get(name) || new THREE.Matrix4();
      m.compose(new THREE.Vector3(p[0], p[1], p[2]),
                new THREE.Quaternion(p[3], p[4], p[5], p[6]), new THREE.Vector3(1, 1, 1));
      ctx.poses.set(name, m);
    }
  };
  const setTree = (tree) => {
    ctx.parents = new Map(tree);
    const names = [...new Set([...tree.flat(), ctx.fixed])].filter(Boolean).sort();
    const current = [...fixedSelect.options].map((o) => o.value).join('\n');
    if (current !== names.join('\n')) {
      fixedSelect.replaceChildren(...names.map((n) => el('option', { value: n, textContent: n })));
    }
    fixedSelect.value = ctx.fixed;
    const boxes = names.map((name) => {
      const box = el('input', { type: 'checkbox', checked: !ctx.hidden.has(name) });
      box.dataset.frame = name;
      box.addEventListener('change', () => {
        if (box.checked) ctx.hidden.delete(name); else ctx.hidden.add(name);
        model.set('hidden_frames', [...ctx.hidden].sort());
        model.save_changes();
        for (const d of displays.values()) d.frames?.();
        wake();
      });
      return el('label', {}, box, ' ' + name);
    });
    framesBox.replaceChildren(framesBox.firstChild, ...boxes);
    root.dataset.tree = String(names.length);
  };
  fixedSelect.addEventListener('change', () => {
    model.set('fixed_frame', fixedSelect.value);
    model.save_changes();
  });

  const addDisplay = (spec) => {
    const Kind = DISPLAYS[spec.kind];
    if (!Kind) { ctx.notes.set(spec.id, [`${spec.id}: this page's bundle has no ${spec.kind} display`]); return; }
    displays.get(spec.id)?.dispose();
    displays.set(spec.id, new Kind(ctx, spec));
  };
  const take = (msg, buffers) => {
    const bufs = (buffers || []).map(bytes);
    if (msg.kind === 'reset') {
      for (const d of displays.values()) d.dispose();
      displays.clear();
      ctx.notes.clear();
      ctx.poses.clear();
      ctx.fixed = msg.fixed;
      root.dataset.fixed = msg.fixed;
      for (const spec of msg.displays) addDisplay(spec);
    }
    if (msg.fixed !== undefined && msg.kind !== 'reset') {
      ctx.fixed = msg.fixed;
      root.dataset.fixed = msg.fixed;
      fixedSelect.value = msg.fixed;
    }
    if (msg.meshes) ctx.meshes.add(msg.meshes, bufs);
    if (msg.add) for (const spec of msg.add) addDisplay(spec);
    if (msg.remove) for (const id of msg.remove) { displays.get(id)?.dispose(); displays.delete(id); ctx.notes.delete(id); }
    if (msg.tree) setTree(msg.tree);
    if (msg.poses) {
      setPoses(msg.poses);
      root.dataset.poses = String(+(root.dataset.poses || 0) + 1);
      for (const d of displays.values()) d.frames?.();
    }
    if (msg.data) {
      for (const [id, data] of Object.entries(msg.data)) displays.get(id)?.update(data, bufs);
    }
    wake();
  };
  model.on('msg:custom', take);
  const changed = () => { showStatus(); wake(); };
  model.on('change:status', changed);
  const hiddenChanged = () => {  // set from Python: view.hide_frames([...])
    ctx.hidden = new Set(model.get('hidden_frames') || []);
    for (const box of framesBox.querySelectorAll('input')) {
      box.checked = !ctx.hidden.has(box.dataset.frame);
    }
    for (const d of displays.values()) d.frames?.();
    wake();
  };
  model.on('change:hidden_frames', hiddenChanged);
  // Where view.look_at put the camera (eye, then the orbit's target, in the fixed frame):
  // read at each render, so a page drawn again or reloaded starts there too.
  const aim = () => {
    const c = model.get('camera') || [];
    if (c.length !== 6) return;
    camera.position.set(c[0], c[1], c[2]);
    controls.target.set(c[3], c[4], c[5]);
    controls.update();
    root.dataset.camera = c.join(',');
    wake();
  };
  aim();
  model.on('change:camera', aim);
  model.send({ kind: 'ready', view: viewId });
  wake();
  return () => {
    stopped = true;
    try { model.send({ kind: 'seen', view: viewId, value: false }); } catch (err) { /* kernel gone */ }
    cancelAnimationFrame(handle);
    resize.disconnect();
    watch.disconnect();
    model.off('msg:custom', take);
    model.off('change:status', changed);
    model.off('change:hidden_frames', hiddenChanged);
    model.off('change:camera', aim);
    for (const d of displays.values()) d.dispose();
    controls.dispose();
    renderer.dispose();
  };
}

export default { render };
