// The page shades as `isowall render` does: its GLSL ES 3.00 shaders are render/gl_core.cpp's GLSL
// 3.30 ones, statement for statement (the version line, the fragment shader's precision line and
// comments aside), so a change to one without the other fails here.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { kFragmentShader, kVertexShader } from '../src/renderer.js';

const core = readFileSync(new URL('../../render/gl_core.cpp', import.meta.url), 'utf8');

function cppShader(name) {
  const m = new RegExp(`constexpr const char\\* ${name} = R"\\(([\\s\\S]*?)\\)";`).exec(core);
  assert.ok(m, `render/gl_core.cpp: no ${name}`);
  return m[1];
}

// The statements of a shader: no version or precision line, no comments, no blank lines.
function statements(source) {
  return source.split('\n').map((l) => l.replace(/\/\/.*$/, '').trim())
    .filter((l) => l && !l.startsWith('#version') && !l.startsWith('precision '));
}

test('the vertex shader is gl_core.cpp\'s', () => {
  assert.ok(kVertexShader.startsWith('#version 300 es\n'));
  assert.deepEqual(statements(kVertexShader), statements(cppShader('kVertexShader')));
});

test('the fragment shader is gl_core.cpp\'s', () => {
  assert.ok(kFragmentShader.startsWith('#version 300 es\nprecision highp float;\n'));
  const page = statements(kFragmentShader);
  assert.deepEqual(page, statements(cppShader('kFragmentShader')));
  assert.ok(page.length > 15, `${page.length} statements`);
});
