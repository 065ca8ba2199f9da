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
# The npm package carries no licence file; vendor/LICENSE-pmtiles is the repository's
# (github.com/protomaps/PMTiles, BSD-3-Clause) and is kept as it is.
printf 'leaflet %s (BSD-2-Clause), ol %s (BSD-2-Clause), pmtiles %s (BSD-3-Clause), from the npm registry via ./vendor.sh\n' \
  "$(node -p 'require("./node_modules/leaflet/package.json").version')" \
  "$(node -p 'require("./node_modules/ol/package.json").version')" \
  "$(node -p 'require("./node_modules/pmtiles/package.json").version')" > vendor/VERSIONS
rm -rf node_modules
