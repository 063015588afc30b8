// Builds bridges/viewer/vendor/three-vrm.bundle.js (one minified ES module) and copies the
// libraries' licence texts next to it. Run: npm ci && npm run build (README.md in this folder).
import { build } from "esbuild";
import { copyFileSync, mkdirSync, statSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

const here = dirname(fileURLToPath(import.meta.url));
const vendor = join(here, "..", "..", "bridges", "viewer", "vendor");
const bundle = join(vendor, "three-vrm.bundle.js");
const LICENSES = {
  "three.LICENSE": "node_modules/three/LICENSE",
  "three-vrm.LICENSE": "node_modules/@pixiv/three-vrm/LICENSE",
  "three-vrm-animation.LICENSE": "node_modules/@pixiv/three-vrm-animation/LICENSE",
};

mkdirSync(vendor, { recursive: true });
await build({
  entryPoints: [join(here, "entry.mjs")],
  bundle: true,
  format: "esm",
  minify: true,
  legalComments: "eof",
  target: "es2020",
  outfile: bundle,
});
for (const [name, source] of Object.entries(LICENSES)) copyFileSync(join(here, source), join(vendor, name));
console.log(`${bundle}: ${statSync(bundle).size} bytes`);
