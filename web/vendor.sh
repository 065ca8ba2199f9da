#!/usr/bin/env bash
# Refresh web/vendor/ from the npm registry at the versions pinned in package.json /
# package-lock.json. The copied files are committed, so building textile needs no npm.
set -euo pipefail
cd "$(dirname "$0")"
npm ci --no-audit --no-fund
find vendor -type f ! -name LICENSE-pmtiles -delete 2>/dev/null || true; mkdir -p vendor
cp node_modules/leaflet/dist/leaflet.js node_modules/leaflet/dist/leaflet.css vendor/
cp node_modules/leaflet/LICENSE vendor/LICENSE-leaflet
cp node_modules/ol/dist/ol.js vendor/ol.js
cp node_modules/ol/ol.css vendor/ol.css
cp node_modules/ol/LICENSE.md vendor/LICENSE-ol.md
cp node_modules/pmtiles/dist/pmtiles.js vendor/pmtiles.js
# MapLibre GL JS (its UMD build: one script, its worker inlined) for the terrain page.
cp node_modules/maplibre-gl/dist/maplibre-gl.js node_modules/maplibre-gl/dist/maplibre-gl.css vendor/
cp node_modules/maplibre-gl/LICENSE.txt vendor/LICENSE-maplibre-gl
# three.js (the build and the addons the 3D page and 3DTilesRendererJS import) and
# 3DTilesRendererJS (its ES build: the renderer and the core plugins, implicit tiling among them).
mkdir -p vendor/three/addons/loaders vendor/three/addons/utils vendor/three/addons/controls vendor/3d-tiles-renderer
cp node_modules/three/build/three.module.js node_modules/three/build/three.core.js vendor/three/
cp node_modules/three/examples/jsm/loaders/GLTFLoader.js vendor/three/addons/loaders/
cp node_modules/three/examples/jsm/utils/BufferGeometryUtils.js node_modules/three/examples/jsm/utils/SkeletonUtils.js vendor/three/addons/utils/
cp node_modules/three/examples/jsm/controls/MapControls.js node_modules/three/examples/jsm/controls/OrbitControls.js vendor/three/addons/controls/
cp node_modules/three/LICENSE vendor/LICENSE-three
t=node_modules/3d-tiles-renderer/build
cp "$t/index.js" "$t/index.core-plugins.js" vendor/3d-tiles-renderer/
for f in $(grep -oh '"\./[A-Za-z0-9_-]*\.js"' "$t/index.js" "$t/index.core-plugins.js" | tr -d '"' | sort -u); do
  cp "$t/$f" vendor/3d-tiles-renderer/
done
cp node_modules/3d-tiles-renderer/LICENSE vendor/LICENSE-3d-tiles-renderer
# The npm package carries no licence file; vendor/LICENSE-pmtiles is the repository's
# (github.com/protomaps/PMTiles, BSD-3-Clause) and is kept as it is.
printf 'leaflet %s (BSD-2-Clause), ol %s (BSD-2-Clause), pmtiles %s (BSD-3-Clause), three %s (MIT), 3d-tiles-renderer %s (Apache-2.0), maplibre-gl %s (BSD-3-Clause), from the npm registry via ./vendor.sh\n' \
  "$(node -p 'require("./node_modules/leaflet/package.json").version')" \
  "$(node -p 'require("./node_modules/ol/package.json").version')" \
  "$(node -p 'require("./node_modules/pmtiles/package.json").version')" \
  "$(node -p 'require("./node_modules/three/package.json").version')" \
  "$(node -p 'require("./node_modules/3d-tiles-renderer/package.json").version')" \
  "$(node -p 'require("./node_modules/maplibre-gl/package.json").version')" > vendor/VERSIONS
rm -rf node_modules
