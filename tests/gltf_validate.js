// Test helper: validates glTF assets with the Khronos glTF validator (npm package gltf-validator).
// usage: node gltf_validate.js FILE.gltf|FILE.glb...
// Prints per file the counts of errors, warnings, infos and hints, and every error and warning;
// exits 0 when no file has an error or a warning, 1 when one has, 2 when the validator is missing.
'use strict';
const fs = require('fs');
const path = require('path');

let validator;
try {
    validator = require('gltf-validator');
} catch (e) {
    console.error('gltf_validate: the npm package gltf-validator is not installed (run .ci/setup)');
    process.exit(2);
}

async function validate(file) {
    const data = fs.readFileSync(file);
    const report = await validator.validateBytes(new Uint8Array(data), {
        uri: path.basename(file),
        maxIssues: 0,
        externalResourceFunction: (uri) => new Promise((resolve, reject) => {
            const target = path.resolve(path.dirname(file), decodeURIComponent(uri));
            fs.readFile(target, (err, bytes) => err ? reject(err.toString()) : resolve(new Uint8Array(bytes)));
        }),
    });
    const i = report.issues;
    console.log(`${file}: validator ${report.validatorVersion}: ${i.numErrors} errors, ${i.numWarnings} warnings, ` +
                `${i.numInfos} infos, ${i.numHints} hints; ${report.info ? report.info.totalTriangleCount : '?'} triangles, ` +
                `${report.info ? report.info.totalVertexCount : '?'} vertices`);
    for (const m of i.messages)
        if (m.severity <= 1)
            console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} at ${m.pointer}: ${m.message}`);
    for (const m of i.messages)
        if (m.severity > 1)
            console.log(`  ${m.severity === 2 ? 'info' : 'hint'} ${m.code} at ${m.pointer}: ${m.message}`);
    return i.numErrors === 0 && i.numWarnings === 0;
}

(async () => {
    let ok = true;
    for (const file of process.argv.slice(2)) {
        try {
            ok = (await validate(file)) && ok;
        } catch (e) {
            console.log(`${file}: the validator could not read it: ${e}`);
            ok = false;
        }
    }
    process.exit(ok ? 0 : 1);
})();
