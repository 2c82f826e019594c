// The displays, as RViz names them. Each is built from the kernel's spec, takes its data
// (`update`), follows the frames' poses (`frames`) and leaves no GPU memory behind
// (`dispose`). A new display kind is one class here plus one entry in DISPLAYS, and its
// Python twin in robot_lab/scene/displays.py.
import * as THREE from 'three';
import URDFLoader from 'urdf-loader/src/URDFLoader.js';

const WHITE = new THREE.MeshPhongMaterial({ color: 0xffffff });

function disposeTree(root) {
  root.traverse((o) => {
    o.geometry?.dispose();
    const mats = Array.isArray(o.material) ? o.material : o.material ? [o.material] : [];
    for (const m of mats) { if (m !== WHITE) { m.map?.dispose(); m.dispose(); } }
  });
}

// ROS colours are what the screen shows (RViz applies no gamma): sRGB, not linear.
function colour(rgba, fallback) {
  const c = rgba || fallback;
  return new THREE.Color().setRGB(c[0], c[1], c[2], THREE.SRGBColorSpace);
}

function material(rgba, fallback = [1, 1, 1, 1]) {
  const c = rgba || fallback;
  const alpha = c.length > 3 ? c[3] : 1;
  return new THREE.MeshPhongMaterial({
    color: colour(c), opacity: alpha, transparent: alpha < 1, depthWrite: alpha >= 1,
  });
}

function setPose(obj, p) {  // p: [x, y, z, qx, qy, qz, qw]
  obj.position.set(p[0], p[1], p[2]);
  obj.quaternion.set(p[3], p[4], p[5], p[6]);
}

// An arrow along +x: `length` long, its shaft `shaft` and its head `head` wide.
function arrow(length, shaft, head, mat, headLength = 0.23 * length) {
  const group = new THREE.Group();
  const shaftLength = Math.max(0, length - headLength);
  const body = new THREE.Mesh(new THREE.CylinderGeometry(shaft / 2, shaft / 2, shaftLength, 16), mat);
  body.rotation.z = -Math.PI / 2;
  body.position.x = shaftLength / 2;
  const tip = new THREE.Mesh(new THREE.ConeGeometry(head / 2, headLength, 16), mat);
  tip.rotation.z = -Math.PI / 2;
  tip.position.x = shaftLength + headLength / 2;
  group.add(body, tip);
  return group;
}

function textSprite(text, heightM, rgba = [1, 1, 1, 1]) {
  const pad = 4, px = 48;
  const canvas = document.createElement('canvas');
  const g = canvas.getContext('2d');
  g.font = `${px}px sans-serif`;
  canvas.width = Math.ceil(g.measureText(text).width) + 2 * pad;
  canvas.height = px + 2 * pad;
  g.font = `${px}px sans-serif`;
  g.fillStyle = `rgba(${rgba[0] * 255},${rgba[1] * 255},${rgba[2] * 255},${rgba[3] ?? 1})`;
  g.textBaseline = 'middle';
  g.fillText(text, pad, canvas.height / 2);
  const map = new THREE.CanvasTexture(canvas);
  map.colorSpace = THREE.SRGBColorSpace;
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({ map, depthTest: false, transparent: true }));
  sprite.scale.set(heightM * canvas.width / canvas.height, heightM, 1);
  sprite.renderOrder = 10;
  return sprite;
}

class Display {
  constructor(ctx, spec) {
    this.ctx = ctx;
    this.spec = spec;
    this.group = new THREE.Group();
    ctx.scene.add(this.group);
  }

  // Put `node` where `frame` is in the fixed frame; hide it when there is no transform.
  place(node, frame) {
    const m = this.ctx.poses.get(frame);
    node.matrixAutoUpdate = false;
    if (m) node.matrix.copy(m);
    node.visible = !!m;
    node.matrixWorldNeedsUpdate = true;
    return !!m;
  }

  update() {}

  dispose() {
    this.ctx.scene.remove(this.group);
    disposeTree(this.group);
  }
}

class Grid extends Display {
  constructor(ctx, spec) {
    super(ctx, spec);
    const cells = spec.cells ?? 10, size = spec.size ?? 1;
    const c = colour(spec.color, [160 / 255, 160 / 255, 164 / 255]);
    const grid = new THREE.GridHelper(cells * size, cells, c, c);
    grid.rotation.x = Math.PI / 2;  // three's grid lies in x-z; RViz's in x-y
    this.group.add(grid);
  }
}

class RobotModel extends Display {
  constructor(ctx, spec) {
    super(ctx, spec);
    this.links = new Map();
    this.prefix = spec.prefix || '';
    this.pending = 0;
    this.loaded = false;
    this.reported = false;
    this.ctx.root.dataset.robot = 'waiting';
  }

  update(data) {
    if (data.urdf === undefined) return;
    for (const link of this.links.values()) {  // a new description: free the old robot
      this.group.remove(link);
      disposeTree(link);
    }
    this.links.clear();
    this.ctx.notes.delete(this.spec.id);
    const notes = [];
    const loader = new URDFLoader();
    const manager = new THREE.LoadingManager();
    manager.setURLModifier((url) => this.ctx.meshes.url(url));
    loader.manager = manager;
    loader.packages = (pkg) => 'package://' + pkg;  // keep the URDF's own names: the kernel keyed by them
    this.pending = 1;
    this.loaded = false;
    this.reported = false;
    this.ctx.root.dataset.robot = 'loading';
    const settle = () => {
      this.pending -= 1;
      if (this.pending === 0) {
        this.loaded = true;
        this.ctx.root.dataset.robot = 'loaded';
        if (notes.length) this.ctx.notes.set(this.spec.id, notes);
        this.frames();
        this.ctx.wake();
      }
    };
    loader.loadMeshCb = (path, _manager, mat, done) => {
      this.pending += 1;
      this.ctx.meshes.load(path, mat).then((obj) => done(obj), (err) => {
        notes.push(`RobotModel: cannot load mesh ${err.message}`);
        done(null, err);
      }).finally(() => { this.frames(); settle(); });
    };
    let robot;
    try {
      robot = loader.parse(data.urdf);
    } catch (err) {
      this.ctx.notes.set(this.spec.id, [`RobotModel: the URDF does not parse: ${err.message}`]);
      return;
    }
    // RViz places every link by its own TF frame, not by the joints: take the links out of
    // the joint tree, each a direct child of this display.
    for (const [name, link] of Object.entries(robot.links)) {
      this.links.set(name, link);
    }
    for (const link of this.links.values()) {
      this.group.add(link);
      link.matrixAutoUpdate = false;
    }
    this.ctx.root.dataset.links = String(this.links.size);
    settle();
  }

  frames() {
    for (const [name, link] of this.links) {
      const m = this.ctx.poses.get(this.prefix + name);
      link.matrix.copy(m || new THREE.Matrix4());
      link.matrixWorldNeedsUpdate = true;
      const white = !m;
      // A link with no transform: at the origin, white (as RViz draws it)
      link.traverse((o) => {
        if (!o.isMesh) return;
        if (o.userData.rlOwnLink === undefined) o.userData.rlOwnLink = name;
        if (o.userData.rlOwnLink !== name) return;  // a child link's mesh, if any remains
        if (o.userData.rlMaterial === undefined) o.userData.rlMaterial = o.material;
        o.material = white ? WHITE : o.userData.rlMaterial;
      });
    }
  }

  beforeRender() {
    if (!this.links.size) return;
    const box = new THREE.Box3().setFromObject(this.group);
    if (box.isEmpty()) return;
    const { canvas, camera } = this.ctx;
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    for (const x of [box.min.x, box.max.x]) for (const y of [box.min.y, box.max.y]) {
      for (const z of [box.min.z, box.max.z]) {
        const v = new THREE.Vector3(x, y, z).project(camera);
        const sx = (v.x + 1) / 2 * canvas.clientWidth, sy = (1 - v.y) / 2 * canvas.clientHeight;
        x0 = Math.min(x0, sx); x1 = Math.max(x1, sx); y0 = Math.min(y0, sy); y1 = Math.max(y1, sy);
      }
    }
    this.ctx.root.dataset.robotBox = [x0, y0, x1, y1].map((v) => v.toFixed(1)).join(',');
    if (this.loaded && !this.reported) {
      this.reported = true;
      this.ctx.root.dataset.robot = 'drawn';
      this.ctx.root.dataset.robotDrawnAt = String(performance.timeOrigin + performance.now());
    }
  }

  dispose() {
    super.dispose();
    this.ctx.root.dataset.robot = 'none';
  }
}

class TF extends Display {
  constructor(ctx, spec) {
    super(ctx, spec);
    this.scale = spec.scale ?? 1;
    this.nodes = new Map();
    const geometry = new THREE.BufferGeometry();
    this.arrows = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ vertexColors: true }));
    this.arrows.frustumCulled = false;
    this.group.add(this.arrows);
    this.frames();
  }

  node(name) {
    let node = this.nodes.get(name);
    if (node) return node;
    node = new THREE.Group();
    const len = 0.1 * this.scale;
    const axes = new THREE.AxesHelper(len);
    const label = textSprite(name, 0.03 * this.scale);
    label.position.set(0, 0, 0.02 * this.scale);
    label.center.set(0, 0);
    node.add(axes, label);
    this.group.add(node);
    this.nodes.set(name, node);
    return node;
  }

  frames() {
    const { poses, hidden, parents } = this.ctx;
    const segs = [], cols = [];
    for (const [name, m] of poses) {
      const node = this.node(name);
      node.matrixAutoUpdate = false;
      node.visible = !!m && !hidden.has(name);
      if (m) { node.matrix.copy(m); node.matrixWorldNeedsUpdate = true; }
      const parent = parents.get(name);
      const pm = parent ? poses.get(parent) : null;
      if (m && pm && node.visible && !hidden.has(parent)) {
        const a = new THREE.Vector3().setFromMatrixPosition(m);
        const b = new THREE.Vector3().setFromMatrixPosition(pm);
        segs.push(a.x, a.y, a.z, b.x, b.y, b.z);
        cols.push(1, 1, 0, 1, 0, 1);  // yellow at the child, magenta at the parent (RViz)
      }
    }
    const g = this.arrows.geometry;
    g.setAttribute('position', new THREE.Float32BufferAttribute(segs, 3));
    g.setAttribute('color', new THREE.Float32BufferAttribute(cols, 3));
    this.ctx.root.dataset.tfShown = String([...this.nodes.values()].filter((n) => n.visible).length);
  }
}

class LaserScan extends Display {
  constructor(ctx, spec) {
    super(ctx, spec);
    this.frame = null;
    this.holder = new THREE.Group();
    this.group.add(this.holder);
    this.points = new THREE.Points(new THREE.BufferGeometry(), new THREE.PointsMaterial({
      size: spec.point_size ?? 3, sizeAttenuation: false, vertexColors: true }));
    this.points.frustumCulled = false;
    this.holder.add(this.points);
  }

  update(data, buffers) {
    this.frame = data.frame;
    const ranges = new Float32Array(buffers[data.ranges].slice().buffer);
    const inten = data.intensities !== undefined
      ? new Float32Array(buffers[data.intensities].slice().buffer) : null;
    let lo = Infinity, hi = -Infinity;
    if (inten) for (const v of inten) { if (v < lo) lo = v; if (v > hi) hi = v; }
    const useIntensity = inten && hi > lo;
    const flat = colour(this.spec.color, [1, 0, 0]);
    const pos = [], col = [];
    const c = new THREE.Color();
    for (let i = 0; i < ranges.length; i++) {
      const r = ranges[i];
      if (!(r >= data.range_min && r <= data.range_max)) continue;
      const a = data.angle_min + i * data.angle_increment;
      pos.push(r * Math.cos(a), r * Math.sin(a), 0);
      if (useIntensity) c.setHSL(0.8 * (1 - (inten[i] - lo) / (hi - lo)), 1, 0.5); else c.copy(flat);
      col.push(c.r, c.g, c.b);
    }
    const g = this.points.geometry;
    g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
    this.frames();
  }

  frames() { if (this.frame !== null) this.place(this.holder, this.frame); }
}

// Marker and MarkerArray (and shapes the kernel draws itself, such as a simulated world).
class Markers extends Display {
  constructor(ctx, spec) {
    super(ctx, spec);
    this.items = new Map();  // 'ns/id' -> {node, frame}
  }

  update(data) {
    for (const op of data.ops || []) {
      if (op.action === 3) {  // DELETEALL
        for (const key of [...this.items.keys()]) {
          if (!op.ns || key.startsWith(op.ns + '/')) this.drop(key);
        }
        continue;
      }
      this.drop(op.key);
      if (op.action === 2) continue;  // DELETE
      const node = new THREE.Group();
      const inner = this.build(op);
      if (!inner) continue;
      setPose(inner, op.pose);
      node.add(inner);
      this.group.add(node);
      this.items.set(op.key, { node, frame: op.frame });
      this.place(node, op.frame);
    }
  }

  drop(key) {
    const item = this.items.get(key);
    if (!item) return;
    this.group.remove(item.node);
    disposeTree(item.node);
    this.items.delete(key);
  }

  build(m) {
    const s = m.scale, mat = () => material(m.color);
    const pts = m.points || [];
    const vec = (i) => new THREE.Vector3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
    const n = pts.length / 3;
    const pointColours = (geometry) => {
      if (!m.colors || m.colors.length / 4 !== n) return false;
      const cols = [];
      const c = new THREE.Color();
      for (let i = 0; i < n; i++) {
        c.setRGB(m.colors[4 * i], m.colors[4 * i + 1], m.colors[4 * i + 2], THREE.SRGBColorSpace);
        cols.push(c.r, c.g, c.b);
      }
      geometry.setAttribute('color', new THREE.Float32BufferAttribute(cols, 3));
      return true;
    };
    switch (m.type) {
      case 0: {  // ARROW
        if (n >= 2) {
          const a = vec(0), b = vec(1), d = b.clone().sub(a), len = d.length();
          const headLen = s[2] > 0 ? s[2] : 0.23 * len;
          const g = arrow(len, s[0], s[1], mat(), Math.min(headLen, len));
          g.position.copy(a);
          g.quaternion.setFromUnitVectors(new THREE.Vector3(1, 0, 0), d.normalize());
          const wrap = new THREE.Group();
          wrap.add(g);
          return wrap;
        }
        return arrow(s[0], s[1], s[2], mat());
      }
      case 1: case 2: case 3: {  // CUBE, SPHERE, CYLINDER
        const geometry = m.type === 1 ? new THREE.BoxGeometry(1, 1, 1)
          : m.type === 2 ? new THREE.SphereGeometry(0.5, 24, 16)
            : new THREE.CylinderGeometry(0.5, 0.5, 1, 24);
        const mesh = new THREE.Mesh(geometry, mat());
        if (m.type === 3) mesh.rotation.x = Math.PI / 2;  // three's cylinders stand on y; ROS's on z
        const g = new THREE.Group();
        g.scale.set(s[0], s[1], s[2]);
        g.add(mesh);
        return g;
      }
      case 4: case 5: {  // LINE_STRIP, LINE_LIST
        const geometry = new THREE.BufferGeometry().setFromPoints([...Array(n).keys()].map(vec));
        const coloured = pointColours(geometry);
        const lm = new THREE.LineBasicMaterial({ color: coloured ? 0xffffff : colour(m.color), vertexColors: coloured });
        return m.type === 4 ? new THREE.Line(geometry, lm) : new THREE.LineSegments(geometry, lm);
      }
      case 6: case 7: {  // CUBE_LIST, SPHERE_LIST
        const geometry = m.type === 6 ? new THREE.BoxGeometry(s[0], s[1], s[2])
          : new THREE.SphereGeometry(0.5, 16, 12).scale(s[0], s[1], s[2]);
        const mesh = new THREE.InstancedMesh(geometry, mat(), Math.max(1, n));
        mesh.count = n;
        const t = new THREE.Matrix4();
        for (let i = 0; i < n; i++) {
          mesh.setMatrixAt(i, t.makeTranslation(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]));
          if (m.colors && m.colors.length / 4 === n) {
            mesh.setColorAt(i, colour(m.colors.slice(4 * i, 4 * i + 3)));
          }
        }
        return mesh;
      }
      case 8: {  // POINTS
        const geometry = new THREE.BufferGeometry().setFromPoints([...Array(n).keys()].map(vec));
        const coloured = pointColours(geometry);
        return new THREE.Points(geometry, new THREE.PointsMaterial({
          size: s[0], color: coloured ? 0xffffff : colour(m.color), vertexColors: coloured }));
      }
      case 9:  // TEXT_VIEW_FACING
        return textSprite(m.text || '', s[2] || 0.1, m.color);
      case 10: {  // MESH_RESOURCE
        const g = new THREE.Group();
        g.scale.set(s[0], s[1], s[2]);
        const own = mat();
        this.ctx.meshes.load(m.mesh, own).then((obj) => {
          if (!m.use_embedded) obj.traverse((o) => { if (o.isMesh) o.material = own; });
          g.add(obj);
          this.ctx.wake();
        }, (err) => {
          this.ctx.notes.set(this.spec.id, [`${this.spec.id}: cannot load mesh ${err.message}`]);
          this.ctx.wake();
        });
        return g;
      }
      case 11: {  // TRIANGLE_LIST
        const geometry = new THREE.BufferGeometry().setFromPoints([...Array(n).keys()].map(vec));
        geometry.computeVertexNormals();
        const coloured = pointColours(geometry);
        const tm = material(m.color);
        tm.side = THREE.DoubleSide;
        if (coloured) { tm.vertexColors = true; tm.color.set(0xffffff); }
        return new THREE.Mesh(geometry, tm);
      }
      default:
        this.ctx.notes.set(this.spec.id, [`${this.spec.id}: marker type ${m.type} is not one RViz draws`]);
        return null;
    }
  }

  frames() { for (const item of this.items.values()) this.place(item.node, item.frame); }
}

class Path extends Display {
  constructor(ctx, spec) {
    super(ctx, spec);
    this.frame = null;
    this.line = new THREE.Line(new THREE.BufferGeometry(),
      new THREE.LineBasicMaterial({ color: colour(spec.color, [25 / 255, 1, 0]) }));
    this.line.frustumCulled = false;
    this.holder = new THREE.Group();
    this.holder.add(this.line);
    this.group.add(this.holder);
  }

  update(data) {
    this.frame = data.frame;
    this.line.geometry.setAttribute('position', new THREE.Float32BufferAttribute(data.points, 3));
    this.frames();
  }

  frames() { if (this.frame !== null) this.place(this.holder, this.frame); }
}

// Odometry (the last `keep` poses, as arrows) and PoseStamped (one arrow).
class Poses extends Display {
  constructor(ctx, spec) {
    super(ctx, spec);
    this.frame = null;
    this.holder = new THREE.Group();
    this.group.add(this.holder);
    this.mat = material(spec.color, spec.kind === 'pose' ? [1, 25 / 255, 0, 1] : [1, 0, 0, 1]);
  }

  update(data) {
    this.frame = data.frame;
    for (const child of [...this.holder.children]) {
      this.holder.remove(child);
      child.traverse((o) => o.geometry?.dispose());
    }
    const len = this.spec.length ?? (this.spec.kind === 'pose' ? 1 : 0.5);
    const p = data.poses;
    for (let i = 0; i + 7 <= p.length; i += 7) {
      const a = arrow(len, 0.05 * len / 0.5 * 0.5, 0.1 * len / 0.5 * 0.5, this.mat, 0.3 * len);
      setPose(a, p.slice(i, i + 7));
      this.holder.add(a);
    }
    this.frames();
  }

  frames() { if (this.frame !== null) this.place(this.holder, this.frame); }

  dispose() {
    super.dispose();
    this.mat.dispose();
  }
}

export const DISPLAYS = {
  grid: Grid,
  robot_model: RobotModel,
  tf: TF,
  laser_scan: LaserScan,
  markers: Markers,
  path: Path,
  odometry: Poses,
  pose: Poses,
};
