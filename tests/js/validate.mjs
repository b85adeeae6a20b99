// Validates glTF files with the Khronos glTF-Validator (npm `gltf-validator`).
//
// Usage: node tests/js/validate.mjs FILE.glb [FILE.gltf ...]
// Prints one JSON line per file:
//   {"file", "errors", "warnings", "infos", "hints", "messages": [{code, severity, pointer, message}],
//    "codes": {"severity:CODE": count}}
// ("messages" lists the first 20 errors and warnings; "codes" counts every message by
// "severity:CODE", e.g. {"warning:NODE_SKINNED_MESH_NON_ROOT": 1}). Exit code 1 when any file has an error or
// cannot be read or parsed, 2 on bad usage.

import { readFile } from "node:fs/promises";
import path from "node:path";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const validator = require("gltf-validator");

const SEVERITY = ["error", "warning", "info", "hint"];
const MAX_MESSAGES = 20;

async function validate(file) {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))).then(
        (data) => new Uint8Array(data),
      ),
  });
  const issues = report.issues;
  const codes = {};
  for (const m of issues.messages) {
    const key = `${SEVERITY[m.severity] ?? m.severity}:${m.code}`;
    codes[key] = (codes[key] ?? 0) + 1;
  }
  return {
    file,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    messages: issues.messages
      .filter((m) => m.severity <= 1)
      .slice(0, MAX_MESSAGES)
      .map((m) => ({
        code: m.code,
        severity: SEVERITY[m.severity] ?? String(m.severity),
        pointer: m.pointer ?? null,
        message: m.message,
      })),
    codes,
  };
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error("usage: node tests/js/validate.mjs FILE.glb [FILE ...]");
  process.exit(2);
}
let failed = false;
for (const file of files) {
  try {
    const result = await validate(file);
    failed ||= result.errors > 0;
    console.log(JSON.stringify(result));
  } catch (error) {
    failed = true;
    console.log(JSON.stringify({ file, errors: 1, fatal: String(error) }));
  }
}
process.exit(failed ? 1 : 0);
