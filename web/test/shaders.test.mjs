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

// The server forecasts the colours the client shows (remote/lod_choice.cpp) from
// render/headlight.h: its constants are the fragment shader's.
test('render/headlight.h holds the fragment shader\'s constants', () => {
  const header = readFileSync(new URL('../../render/headlight.h', import.meta.url), 'utf8');
  const shader = cppShader('kFragmentShader');
  const numbers = (s) => s.split(',').map((x) => Number(x.trim().replace(/f$/, '')));
  let checked = 0;
  for (const m of shader.matchAll(/const (float|vec3) (k\w+) = (?:vec3\()?([^;)]+)\)?;/g)) {
    const h = new RegExp(`${m[2]}(?:\\{([^}]*)\\}| = ([^;]+));`).exec(header);
    assert.ok(h, `render/headlight.h: no ${m[2]}`);
    assert.deepEqual(numbers(h[1] ?? h[2]), numbers(m[3]), m[2]);
    ++checked;
  }
  assert.equal(checked, 6);
});
