// Validate glTF/GLB files with the Khronos glTF validator; print one JSON
// report per file (an array) on stdout.  Used by tests/test_io_gltf.py.
const fs = require("fs");
const path = require("path");
const validator = require("gltf-validator");

async function main(files) {
  const reports = [];
  for (const file of files) {
    const data = new Uint8Array(fs.readFileSync(file));
    reports.push(await validator.validateBytes(data, { uri: path.basename(file), maxIssues: 0 }));
  }
  process.stdout.write(JSON.stringify(reports));
}

main(process.argv.slice(2)).catch((err) => {
  process.stderr.write(String(err) + "\n");
  process.exit(1);
});
