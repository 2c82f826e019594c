// Rebuild robot_lab's 3D view bundle: `npm ci && npm run build` in this folder.
// Writes robot_lab/data/scene_view.js, a minified ES module that anywidget loads as the
// widget's _esm; it is committed, so `pip install robot_lab` needs no node.
import { build } from 'esbuild';
import { fileURLToPath } from 'node:url';
import path from 'node:path';

const here = path.dirname(fileURLToPath(import.meta.url));
const out = path.join(here, '..', '..', 'robot_lab', 'data', 'scene_view.js');
const result = await build({
  entryPoints: [path.join(here, 'src', 'scene.js')],
  bundle: true,
  format: 'esm',
  minify: true,
  target: 'es2020',
  legalComments: 'eof',
  metafile: true,
  outfile: out,
  banner: { js: '// robot_lab scene_view bundle: built from js/scene_view (three, urdf-loader); do not edit.' },
});
const bytes = Object.values(result.metafile.outputs)[0].bytes;
console.log(`${path.relative(process.cwd(), out)}: ${(bytes / 1024).toFixed(0)} KiB`);
