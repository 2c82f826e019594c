// Meshes and their textures, as the kernel sent them (bytes keyed by the URDF's own path,
// package:// or file://). Loaders parse bytes, never a URL: nothing leaves the page.
import * as THREE from 'three';
import { STLLoader } from 'three/examples/jsm/loaders/STLLoader.js';
import { ColladaLoader } from 'three/examples/jsm/loaders/ColladaLoader.js';
import { OBJLoader } from 'three/examples/jsm/loaders/OBJLoader.js';

// A texture the kernel could not find: one white pixel, so the mesh keeps its colours.
const WHITE_PNG = 'data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8/58BAAX+Av7czFnnAAAAAElFTkSuQmCC';

export class MeshStore {
  constructor() {
    this.files = new Map();  // path -> {data: Uint8Array, textures: Map(name -> blob URL)}
    this.urls = [];
  }

  add(meshes, buffers) {
    for (const [path, entry] of Object.entries(meshes)) {
      if (entry.index === null || entry.index === undefined) {
        this.files.set(path, { error: entry.error || 'not sent' });
        continue;
      }
      const textures = new Map();
      for (const [name, index] of Object.entries(entry.textures || {})) {
        const url = URL.createObjectURL(new Blob([buffers[index]]));
        this.urls.push(url);
        textures.set(name, url);
      }
      this.files.set(path, { data: buffers[entry.index], textures });
    }
  }

  has(path) { return this.files.has(path); }

  // A URL for a texture a URDF <material> names: the bytes sent, else one white pixel.
  url(path) {
    const file = this.files.get(path);
    if (!file || !file.data) return WHITE_PNG;
    if (!file.url) {
      file.url = URL.createObjectURL(new Blob([file.data]));
      this.urls.push(file.url);
    }
    return file.url;
  }

  // The mesh at `path` as an Object3D (a material applied where the file has none), or an
  // Error that says why not.
  load(path, material) {
    const file = this.files.get(path);
    if (!file) return Promise.reject(new Error(`${path}: the kernel sent no such mesh`));
    if (file.error) return Promise.reject(new Error(file.error));
    const ext = path.split('?')[0].split('.').pop().toLowerCase();
    try {
      if (ext === 'stl') {
        const geometry = new STLLoader().parse(file.data.slice().buffer);
        geometry.computeVertexNormals();
        const colour = geometry.hasColors ? new THREE.MeshPhongMaterial({ vertexColors: true }) : material;
        return Promise.resolve(new THREE.Mesh(geometry, colour));
      }
      const text = new TextDecoder().decode(file.data);
      if (ext === 'obj') {
        const group = new OBJLoader().parse(text);
        group.traverse((o) => { if (o.isMesh) o.material = material; });
        return Promise.resolve(group);
      }
      if (ext === 'dae') {
        const manager = new THREE.LoadingManager();
        const missing = [];
        manager.setURLModifier((url) => {
          const name = decodeURIComponent(url.split('/').pop());
          const found = file.textures.get(url) || file.textures.get(name);
          if (found) return found;
          missing.push(name);
          return WHITE_PNG;
        });
        const loader = new ColladaLoader(manager);
        const collada = loader.parse(text, '');
        const scene = collada.scene;
        // ColladaLoader turns Z-up files to y-up; ROS is z-up, so undo it (as urdf-loader does)
        scene.rotation.set(0, 0, 0);
        scene.position.set(0, 0, 0);
        return Promise.resolve(scene);
      }
      return Promise.reject(new Error(`${path}: .${ext} meshes are not supported (STL, DAE, OBJ are)`));
    } catch (err) {
      return Promise.reject(new Error(`${path}: ${err.message || err}`));
    }
  }

  dispose() {
    for (const url of this.urls) URL.revokeObjectURL(url);
    this.urls = [];
  }
}
