// Validate glTF / GLB files with the Khronos glTF validator and print one JSON report.
//
//   node tools/gltf-validator/validate.mjs FILE [FILE ...]
//
// Prints {"validator": VERSION, "files": [{"file", "errors", "warnings", "infos", "hints",
// "messages": [{"code", "message", "severity", "pointer"}]}]} (severity 0 error, 1 warning,
// 2 info, 3 hint). External buffers and images are read from the file's folder. Exit status 0
// when every file was read (whatever it holds), 2 for bad arguments or an unreadable file.
import { readFile } from "node:fs/promises";
import path from "node:path";
import validator from "gltf-validator";

async function validate(file) {
  const folder = path.dirname(path.resolve(file));
  const data = await readFile(file);
  const report = await validator.validateBytes(new Uint8Array(data), {
    uri: path.basename(file),
    maxIssues: 1000,
    externalResourceFunction: async (uri) => {
      const target = path.resolve(folder, decodeURIComponent(uri));
      if (path.relative(folder, target).startsWith("..")) {
        throw new Error(`${uri} lies outside the glTF's folder`);
      }
      return new Uint8Array(await readFile(target));
    },
  });
  const issues = report.issues;
  return {
    file,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    messages: issues.messages.map((m) => ({
      code: m.code, message: m.message, severity: m.severity, pointer: m.pointer ?? null,
    })),
  };
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error("usage: node validate.mjs FILE [FILE ...]");
  process.exit(2);
}
try {
  const reports = [];
  for (const file of files) {
    reports.push(await validate(file));
  }
  console.log(JSON.stringify({ validator: validator.version(), files: reports }, null, 1));
} catch (error) {
  console.error(String(error));
  process.exit(2);
}
