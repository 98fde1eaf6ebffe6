// WebGL2 drawing with the surface's shaders (render/shaders/: headlight Phong, front and back
// colours) as GLSL ES 3.00 (src/shaders.js, made by tools/shaders.mjs): depth test LESS, no
// culling (open surfaces show both sides), black background, drawing straight into the canvas
// (preserveDrawingBuffer keeps it between frames).
// Each mesh is uploaded once (positions, normals, uint32 indices) and kept while the client holds
// it; collect() frees the buffers of meshes no longer held.
import { normalMatrix } from './camera.js';
import { kFragmentShader, kVertexShader } from './shaders.js';

export { kFragmentShader, kVertexShader };

export class RendererError extends Error {}

export class Renderer {
  // Throws RendererError when the canvas has no WebGL2.
  constructor(canvas) {
    this.canvas = canvas;
    const gl = canvas.getContext('webgl2', {
      preserveDrawingBuffer: true, antialias: false, alpha: false, depth: true, stencil: false,
      premultipliedAlpha: false,
    });
    if (!gl) throw new RendererError('WebGL2 is not available in this browser');
    this.gl = gl;
    this.program = this.link();
    this.loc = {
      model_view: gl.getUniformLocation(this.program, 'model_view'),
      projection: gl.getUniformLocation(this.program, 'projection'),
      normal_matrix: gl.getUniformLocation(this.program, 'normal_matrix'),
      orthographic: gl.getUniformLocation(this.program, 'orthographic'),
    };
    this.uploaded = new Set();  // meshes with GL buffers
    this.width = canvas.width;
    this.height = canvas.height;
    this.warmUp();
  }

  // The GL compiles its shader variants on the first draw (SwiftShader and Mesa both do, tens of
  // ms): one triangle now, cleared away, so no frame pays it (the engine's warm_up does the same).
  warmUp() {
    const one = { positions: new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0]),
                  normals: new Float32Array([0, 0, 1, 0, 0, 1, 0, 0, 1]), indices: new Uint32Array([0, 1, 2]) };
    const identity = new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
    this.draw(one, identity, identity);
    this.finish();
    this.collect(new Set());
    this.clear();
  }

  // Waits until every GL command so far has run: WebGL draws are queued for another process, so
  // a time taken after finish() is a time the pixels exist (the page's first group and end of frame).
  finish() {
    this.gl.finish();
  }

  compile(type, source) {
    const gl = this.gl;
    const s = gl.createShader(type);
    gl.shaderSource(s, source);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) {
      const log = gl.getShaderInfoLog(s);
      gl.deleteShader(s);
      throw new RendererError(`compiling the ${type === gl.VERTEX_SHADER ? 'vertex' : 'fragment'} shader failed: ${log}`);
    }
    return s;
  }

  link() {
    const gl = this.gl;
    const p = gl.createProgram();
    const v = this.compile(gl.VERTEX_SHADER, kVertexShader);
    const fr = this.compile(gl.FRAGMENT_SHADER, kFragmentShader);
    gl.attachShader(p, v);
    gl.attachShader(p, fr);
    gl.linkProgram(p);
    gl.deleteShader(v);
    gl.deleteShader(fr);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new RendererError(`linking failed: ${gl.getProgramInfoLog(p)}`);
    return p;
  }

  resize(width, height) {
    if (this.canvas.width !== width) this.canvas.width = width;
    if (this.canvas.height !== height) this.canvas.height = height;
    this.width = width;
    this.height = height;
  }

  clear() {
    const gl = this.gl;
    gl.viewport(0, 0, this.width, this.height);
    gl.clearColor(0, 0, 0, 1);
    gl.clearDepth(1);
    gl.depthMask(true);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  }

  clearDepth() {
    const gl = this.gl;
    gl.viewport(0, 0, this.width, this.height);
    gl.clearDepth(1);
    gl.depthMask(true);
    gl.clear(gl.DEPTH_BUFFER_BIT);
  }

  upload(mesh) {
    if (mesh.gl) return mesh.gl;
    const gl = this.gl;
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    const buffers = [];
    for (const [loc, data] of [[0, mesh.positions], [1, mesh.normals]]) {
      const b = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
      gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 12, 0);
      gl.enableVertexAttribArray(loc);
      buffers.push(b);
    }
    const ib = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, mesh.indices, gl.STATIC_DRAW);
    buffers.push(ib);
    gl.bindVertexArray(null);
    mesh.gl = { vao, buffers, count: mesh.indices.length };
    this.uploaded.add(mesh);
    return mesh.gl;
  }

  // view: the camera's look-at matrix; projection: the frustum's (both column-major Float32Array).
  draw(mesh, view, projection) {
    if (mesh.indices.length === 0) return;
    const gl = this.gl;
    const g = this.upload(mesh);
    gl.viewport(0, 0, this.width, this.height);
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(gl.LESS);
    gl.depthMask(true);
    gl.disable(gl.CULL_FACE);
    gl.useProgram(this.program);
    gl.uniformMatrix4fv(this.loc.model_view, false, view);
    gl.uniformMatrix4fv(this.loc.projection, false, projection);
    gl.uniformMatrix3fv(this.loc.normal_matrix, false, normalMatrix(view));
    // A perspective matrix copies -z into w; an orthographic one leaves w at 1.
    gl.uniform1i(this.loc.orthographic, projection[11] === 0 ? 1 : 0);
    gl.bindVertexArray(g.vao);
    gl.drawElements(gl.TRIANGLES, g.count, gl.UNSIGNED_INT, 0);
    gl.bindVertexArray(null);
  }

  // Frees the GL buffers of every uploaded mesh not in `live` (a Set of meshes).
  collect(live) {
    const gl = this.gl;
    for (const mesh of this.uploaded) {
      if (live.has(mesh)) continue;
      gl.deleteVertexArray(mesh.gl.vao);
      for (const b of mesh.gl.buffers) gl.deleteBuffer(b);
      mesh.gl = null;
      this.uploaded.delete(mesh);
    }
  }

  snapshot() {
    return this.canvas.toDataURL('image/png');
  }
}
