// Starts `isowall serve --port 0 --http 0` (and any extra arguments) for the browser checks and
// resolves with { proc, url, port } once it prints its page line; rejects when it exits first or
// says nothing for `timeoutS` seconds (a large dataset's octree may take longer than the default
// 60). The caller stops it with proc.kill('SIGINT').
import { spawn } from 'node:child_process';

export function startServe(bin, extra = [], { log = null, timeoutS = 60 } = {}) {
  const proc = spawn(bin, ['serve', '--port', '0', '--http', '0', ...extra],
    { stdio: ['ignore', 'pipe', 'pipe'] });
  let text = '';
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => {
      proc.kill('SIGKILL');
      reject(new Error(`isowall serve: no page line within ${timeoutS} s: ${text.slice(-300)}`));
    }, timeoutS * 1000);
    const take = (d) => {
      text += d;
      if (log) log(String(d));
      const page = /page at (https?:\/\/\S+)/.exec(text);
      const tcp = /listening on \S+:(\d+)/.exec(text);
      if (page && tcp) {
        clearTimeout(timer);
        resolve({ proc, url: page[1], port: Number(tcp[1]) });
      }
    };
    proc.stdout.on('data', take);
    proc.stderr.on('data', take);
    proc.on('exit', (code) => {
      clearTimeout(timer);
      reject(new Error(`isowall serve exited (${code}): ${text.trim().split('\n').pop()}`));
    });
  });
}
