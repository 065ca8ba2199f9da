// Validate textile's glTF answers with the official Khronos validator; exits non-zero on any
// error or warning. Usage: node validate.mjs BASE_URL PATH [PATH ...]
import validator from 'gltf-validator';

const [base, ...paths] = process.argv.slice(2);
let failed = false;
for (const path of paths) {
  const url = base + path;
  const res = await fetch(url);
  if (!res.ok) { console.error(`${path}: HTTP ${res.status}`); failed = true; continue; }
  const bytes = new Uint8Array(await res.arrayBuffer());
  const external = async (uri) => {
    const r = await fetch(new URL(uri, url));
    if (!r.ok) throw new Error(`${uri}: HTTP ${r.status}`);
    return new Uint8Array(await r.arrayBuffer());
  };
  const report = await validator.validateBytes(bytes, { uri: url, externalResourceFunction: external, maxIssues: 100 });
  const { numErrors, numWarnings, numInfos, numHints, messages } = report.issues;
  console.log(`${path}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints; ` +
    `${report.info.resources.length} resources, ${report.info.drawCallCount} draw calls`);
  for (const m of messages) console.log(`  [${['error', 'warning', 'info', 'hint'][m.severity]}] ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  if (numErrors > 0 || numWarnings > 0) failed = true;
  if (report.info.resources.some((r) => r.storage === 'external' && r.image === undefined && r.mimeType?.startsWith('image/'))) failed = true;
}
process.exit(failed ? 1 : 0);
