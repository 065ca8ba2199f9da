#!/usr/bin/env bash
# Refresh web/vendor/ from the npm registry at the versions pinned in package.json /
# package-lock.json. The copied files are committed, so building textile needs no npm.
set -euo pipefail
cd "$(dirname "$0")"
npm ci --no-audit --no-fund
rm -rf vendor && mkdir -p vendor
cp node_modules/leaflet/dist/leaflet.js node_modules/leaflet/dist/leaflet.css vendor/
cp node_modules/leaflet/LICENSE vendor/LICENSE-leaflet
cp node_modules/ol/dist/ol.js vendor/ol.js
cp node_modules/ol/ol.css vendor/ol.css
cp node_modules/ol/LICENSE.md vendor/LICENSE-ol.md
printf 'leaflet %s (BSD-2-Clause), ol %s (BSD-2-Clause), from the npm registry via ./vendor.sh\n' \
  "$(node -p 'require("./node_modules/leaflet/package.json").version')" \
  "$(node -p 'require("./node_modules/ol/package.json").version')" > vendor/VERSIONS
rm -rf node_modules
