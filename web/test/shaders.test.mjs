// The page shades as `isowall render` does: both compile the one definition in render/shaders/
// (the C++ renderer embeds it at build time; the page's src/shaders.js is made from it by
// tools/shaders.mjs), so src/shaders.js must be what the tool makes from today's files.
// tests/renderer_test.cpp checks render/headlight.h's C++ colours against what GL draws.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { kShadersModule, shadersModule } from '../tools/shaders.mjs';
import { kFragmentShader, kVertexShader } from '../src/renderer.js';

test('src/shaders.js is made from render/shaders/ (run `node tools/shaders.mjs`)', () => {
  assert.equal(readFileSync(kShadersModule, 'utf8'), shadersModule());
});

test('the page\'s shaders are GLSL ES 3.00 with the shared bodies', () => {
  assert.ok(kVertexShader.startsWith('#version 300 es\n'));
  assert.ok(kFragmentShader.startsWith('#version 300 es\nprecision highp float;\n'));
  assert.match(kVertexShader, /gl_Position = projection \* p;/);
  assert.match(kFragmentShader, /uniform bool orthographic;/);
  assert.ok(!/^\s*\/\//m.test(kFragmentShader), 'whole-line comments are left out');
});
