// The Node benches' browser libraries: tests/browser's (installed by `npm ci` there, as
// .ci/run does). Importing this module stops the bench, saying so, when they are missing.
import { createRequire } from 'node:module';

const require = createRequire(new URL('../tests/browser/package.json', import.meta.url));

let playwright;
try {
  playwright = require('playwright-core');
} catch {
  console.error('bench: the browser libraries are missing; install them first: (cd tests/browser && npm ci)');
  process.exit(2);
}

/** Playwright's Chromium launcher. */
export const { chromium } = playwright;
