// Runs `isowall wall` under mpirun for the wall page's browser checks (e2e_wall.mjs): the output
// gathered, and waits on what the master prints, never on a fixed sleep.
import { spawn } from 'node:child_process';

export const mpiEnv = { ...process.env, OMPI_ALLOW_RUN_AS_ROOT: '1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM: '1' };

export class WallRun {
  // `ranks`: 1 + the wall file's tiles; `args`: the wall subcommand's options.
  constructor(bin, ranks, args) {
    this.text = '';
    this.exited = null;
    this.proc = spawn('mpirun', ['--oversubscribe', '-np', String(ranks), bin, 'wall', ...args],
      { env: mpiEnv, stdio: ['ignore', 'pipe', 'pipe'] });
    const take = (d) => { this.text += d; };
    this.proc.stdout.on('data', take);
    this.proc.stderr.on('data', take);
    this.done = new Promise((resolve) => this.proc.on('exit', (code) => { this.exited = code; resolve(code); }));
  }

  // The first match of `re` in the output, within `timeoutS`; throws with the output's tail.
  async waitFor(re, timeoutS = 120) {
    const end = Date.now() + timeoutS * 1000;
    for (;;) {
      const m = re.exec(this.text);
      if (m) return m;
      if (this.exited !== null) throw new Error(`the wall exited (${this.exited}) before ${re}: ${this.tail()}`);
      if (Date.now() > end) throw new Error(`no ${re} within ${timeoutS} s: ${this.tail()}`);
      await new Promise((r) => setTimeout(r, 100));
    }
  }

  // Exit code within `timeoutS`, or null (then killed).
  async exit(timeoutS = 120) {
    let timer;
    const late = new Promise((r) => { timer = setTimeout(() => r(null), timeoutS * 1000); });
    const code = await Promise.race([this.done, late]);
    clearTimeout(timer);  // a pending timer would keep node running until it fires
    if (code === null) this.proc.kill('SIGKILL');
    return code;
  }

  tail() {
    return this.text.trim().split('\n').slice(-8).join(' | ');
  }
}
