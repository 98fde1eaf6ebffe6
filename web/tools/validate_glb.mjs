// Validates binary glTF files with the Khronos glTF validator (npm's gltf-validator) and prints,
// per file, one JSON line: the counts of errors, warnings and infos, their first messages, and
// the validator's summary (vertex and triangle counts). Exit status 1 when a file has an error or
// a warning, 2 when one cannot be read.
//
//   node web/tools/validate_glb.mjs FILE.glb...
import fs from 'node:fs';
import validator from 'gltf-validator';

let status = 0;
for (const file of process.argv.slice(2)) {
  let bytes;
  try {
    bytes = new Uint8Array(fs.readFileSync(file));
  } catch (e) {
    console.error(`validate_glb: ${file}: ${e.message}`);
    status = 2;
    continue;
  }
  const report = await validator.validateBytes(bytes);
  const { numErrors, numWarnings, numInfos, messages } = report.issues;
  console.log(JSON.stringify({
    file, errors: numErrors, warnings: numWarnings, infos: numInfos,
    messages: messages.slice(0, 5).map((m) => `${m.code}: ${m.message} (${m.pointer ?? ''})`),
    vertices: report.info?.totalVertexCount ?? 0, triangles: report.info?.totalTriangleCount ?? 0,
  }));
  if (numErrors + numWarnings > 0 && status === 0) status = 1;
}
process.exit(status);
