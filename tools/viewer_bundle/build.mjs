// Builds bridges/viewer/vendor/three-vrm.bundle.js (one minified ES module) and copies the
// libraries' licence texts next to it. Run: npm ci && npm run build (README.md in this folder).
import { build } from "esbuild";
import { copyFileSync, mkdirSync, readFileSync, statSync } from "node:fs";
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

const versions = JSON.parse(readFileSync(join(here, "package.json"), "utf8")).devDependencies;
const banner = `/* gesturecast viewer bundle (tools/viewer_bundle): three ${versions.three}, @pixiv/three-vrm ` +
  `${versions["@pixiv/three-vrm"]}, @pixiv/three-vrm-animation ${versions["@pixiv/three-vrm-animation"]}; all MIT, ` +
  "licence texts next to this file. */";

mkdirSync(vendor, { recursive: true });
await build({
  entryPoints: [join(here, "entry.mjs")],
  bundle: true,
  format: "esm",
  minify: true,
  legalComments: "eof",
  target: "es2020",
  banner: { js: banner },
  outfile: bundle,
});
for (const [name, source] of Object.entries(LICENSES)) copyFileSync(join(here, source), join(vendor, name));
console.log(`${bundle}: ${statSync(bundle).size} bytes`);
