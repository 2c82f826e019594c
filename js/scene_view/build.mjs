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
  banner: {
    js: '// robot_lab scene_view bundle, built from js/scene_view (do not edit). It contains\n'
      + '// three 0.187.0 (MIT, Copyright 2010-2026 Three.js Authors) and urdf-loader 0.13.1\n'
      + '// (Apache-2.0, https://www.apache.org/licenses/LICENSE-2.0; Garrett Johnson and\n'
      + '// contributors, https://github.com/gkjohnson/urdf-loaders): see js/scene_view/NOTICE.md.',
  },
});
const bytes = Object.values(result.metafile.outputs)[0].bytes;
console.log(`${path.relative(process.cwd(), out)}: ${(bytes / 1024).toFixed(0)} KiB`);
