#!/usr/bin/env node
// The browser page against `isowall view`, in one run: time from sending a request to
// the first group drawn and to the end of the frame, on the phantom and the shared CT head, over
// loopback. One `isowall serve --http 0` serves both clients; each run is a fresh connection (a
// fresh page, a fresh `isowall view` process) asking for the front view with progressive LOD and
// the cache (the study's case 5, compact + zstd), so neither client starts with cached groups.
// The page runs twice: asking for compact+zstd with LOD on as case 5 does (the page's default
// before the cells encoding), and at its defaults since (no parameter: the server chooses cells or
// compact+zstd per group and whether coarse passes go out; the page decodes cells in
// WebAssembly). Runs alternate page / page default / view, so load on this 2-core machine falls
// on all alike. Besides end-to-end times it prints the page's own work in the frame (main-thread
// decoding, GL calls and GL waits, by the page's clock), which the server and link do not move.
//
//   node scripts/bench_page.mjs [--isowall build/bin/isowall] [--runs 5] [--size 800x600]
//                               [--head ../shared/data/vhp_ct_head.nhdr] [--out out/bench-page]
//                               [--no-view]   (the two page runs alone: less load, less spread)
//
// Prints a table of medians (and the fastest run) and writes bench.json and bench.md to --out.
import { spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, readdirSync, readFileSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { startServe } from '../web/test/serve.mjs';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const requireWeb = createRequire(path.join(root, 'web', 'package.json'));

function fail(text) {
    console.error(`bench_page: ${text}`);
    process.exit(1);
}

function parseArgs(argv) {
    const o = {
        isowall: path.join(root, 'build/bin/isowall'),
        runs: 5,
        size: '800x600',
        head: path.join(root, '../shared/data/vhp_ct_head.nhdr'),
        headIso: 40,
        out: path.join(root, 'out/bench-page'),
        timeoutS: 120,
        view: true,
    };
    const numeric = { '--runs': 'runs', '--head-iso': 'headIso', '--timeout': 'timeoutS' };
    const text = { '--isowall': 'isowall', '--size': 'size', '--head': 'head', '--out': 'out' };
    for (let i = 0; i < argv.length; ++i) {
        const a = argv[i];
        if (a === '--no-view') {
            o.view = false;
            continue;
        }
        if (a === '--help' || a === '-h') {
            console.log(readFileSync(fileURLToPath(import.meta.url), 'utf8').split('\n')
                .slice(1, 16).map((l) => l.replace(/^\/\/ ?/, '')).join('\n'));
            process.exit(0);
        }
        const key = numeric[a] ?? text[a];
        if (!key) fail(`unknown option ${a} (see --help)`);
        if (i + 1 >= argv.length) fail(`${a}: expected a value`);
        const v = argv[++i];
        if (numeric[a]) {
            const n = Number(v);
            if (!Number.isFinite(n) || n <= 0) fail(`${a}: expected a positive number, got '${v}'`);
            o[key] = a === '--runs' ? Math.floor(n) : n;
        } else {
            o[key] = v;
        }
    }
    if (!/^\d+x\d+$/.test(o.size)) fail(`--size: expected WIDTHxHEIGHT, got '${o.size}'`);
    if (!existsSync(o.isowall)) fail(`--isowall: no program at ${o.isowall} (build first)`);
    return o;
}

function startServer(o, datasets) {
    const extra = ['--quiet'];
    for (const d of datasets) if (d.path) extra.push('--dataset', `${d.name}=${d.path}`);
    return startServe(o.isowall, extra, { timeoutS: 120 });
}

// The renderer's main-thread CPU seconds so far (DevTools' Performance.getMetrics ThreadTime):
// what the page's frames cost its main thread, whatever else runs on the machine's 2 cores.
async function mainThreadS(cdp) {
    const { metrics } = await cdp.send('Performance.getMetrics');
    const m = metrics.find((x) => x.name === 'ThreadTime');
    if (!m) throw new Error('page: DevTools gave no ThreadTime metric');
    return m.value;
}

async function waitFrame(page, o, afterRequest) {
    await page.waitForFunction(
        (b) => window.isowall && (window.isowall.state === 'error' ||
                                  (window.isowall.state === 'done' && window.isowall.done_request_id > b)),
        afterRequest, { timeout: o.timeoutS * 1000 });
    const s = await page.evaluate(() => ({ ...window.isowall.stats, state: window.isowall.state,
                                           error: window.isowall.error, request_id: window.isowall.request_id }));
    if (s.state === 'error') throw new Error(`page: ${s.error}`);
    // The page's own work in the frame, on its main thread: decoding, issuing GL calls and
    // waiting for the GL (by the page's clock, so preemption on a loaded machine counts in it).
    return { work_ms: s.decode_ms + s.draw_ms + s.gl_wait_ms, first_ms: s.first_group_ms,
             frame_ms: s.frame_ms, bytes: s.bytes, cells: s.cells, triangles: s.triangles,
             groups: s.groups, decode_ms: s.decode_ms, cells_decode_ms: s.cells_decode_ms,
             cells_triangles: s.cells_triangles, draw_ms: s.draw_ms, gl_wait_ms: s.gl_wait_ms,
             request_id: s.request_id };
}

// One fresh page: its first frame (d.iso), then a frame at each of d.more (new isovalues set
// through the slider, as a user would, in the same connection: the server's encoding choice
// and the page's decoders are warm). Returns the first frame's figures and the later ones'.
async function pageRun(browser, server, d, o, encoding) {
    const url = server.url;
    const [w, h] = o.size.split('x').map(Number);
    // The browser's processes are this script's children, beside the server.
    const browserCpu = () => cpuOfTree(process.pid, { skip: [server.proc.pid], withSelf: false });
    const cpu0 = { client: browserCpu(), server: cpuOfTree(server.proc.pid) };
    const page = await browser.newPage({ viewport: { width: w + 400, height: h + 200 } });
    try {
        const cdp = await page.context().newCDPSession(page);
        await cdp.send('Performance.enable');
        // The old default: compact+zstd with LOD on. The page's default: no parameter
        // but the view's (auto encoding, LOD chosen by the server, the cache).
        const q = `?dataset=${encodeURIComponent(d.name)}&size=${o.size}&iso=${d.iso}` +
                  (encoding === undefined ? '' : `&lod=1&cache=1&encoding=${encoding}`);
        let t0 = await mainThreadS(cdp);
        await page.goto(new URL(q, url).href);
        const first = await waitFrame(page, o, 0);
        // The first frame's main-thread CPU includes loading the page (the same for both).
        first.main_ms = 1000 * (await mainThreadS(cdp) - t0);
        first.client_s = browserCpu() - cpu0.client;
        first.server_s = cpuOfTree(server.proc.pid) - cpu0.server;
        const later = [];
        for (const iso of d.more) {
            const before = await page.evaluate(() => window.isowall.request_id);
            t0 = await mainThreadS(cdp);
            await page.locator('#iso-slider').fill(String(iso));
            const f = await waitFrame(page, o, before);
            f.main_ms = 1000 * (await mainThreadS(cdp) - t0);
            later.push(f);
        }
        return { ...first, later };
    } finally {
        await page.close();
    }
}

function viewRun(server, d, o, dir) {
    const port = server.port;
    const csv = path.join(dir, `view-${d.name}.csv`);
    const args = ['view', '--connect', `127.0.0.1:${port}`, '--dataset', d.name, '--case', '5',
                  '--size', o.size, '--iso', String(d.iso), '--timeline', csv,
                  '-o', path.join(dir, `view-${d.name}.png`), '--timeout', String(o.timeoutS)];
    // bash's `times` prints its children's CPU time (user and system) on its second line.
    const server0 = cpuOfTree(server.proc.pid);
    const p = spawnSync('bash', ['-c', '"$@"; rc=$?; times >&2; exit $rc', 'bash', o.isowall, ...args],
                        { encoding: 'utf8', timeout: o.timeoutS * 1000 });
    const server_s = cpuOfTree(server.proc.pid) - server0;
    if (p.status !== 0) throw new Error(`isowall view: ${(p.stderr || p.stdout).trim().split('\n').slice(-2)[0]}`);
    const times = p.stderr.trim().split('\n').pop().match(/(\d+)m([\d.]+)s\s+(\d+)m([\d.]+)s/);
    if (!times) throw new Error(`isowall view: no CPU times from bash: ${p.stderr.trim().split('\n').pop()}`);
    const client_s = 60 * Number(times[1]) + Number(times[2]) + 60 * Number(times[3]) + Number(times[4]);
    const lines = readFileSync(csv, 'utf8').trim().split('\n');
    const head = lines[0].split(',');
    const col = (name) => head.indexOf(name);
    const rows = lines.slice(1).map((l) => l.split(',').map(Number)).filter((r) => r[col('frame')] === 1);
    const first = rows.find((r) => r[col('groups')] >= 1);
    const last = rows[rows.length - 1];
    if (!first || !last) throw new Error('isowall view: the timeline holds no group');
    return { client_s, server_s, first_ms: 1000 * first[col('time_s')], frame_ms: 1000 * last[col('time_s')],
             bytes: last[col('bytes')], triangles: last[col('triangles')], groups: last[col('groups')] };
}

// CPU seconds (user + system) of a process and all its descendants, from /proc: what a run cost
// the browser (its browser, GPU, renderer and network processes) or the server, whatever the
// wall clock on 2 shared cores says.
const kTicks = 100;  // USER_HZ: /proc/PID/stat counts clock ticks of 1/100 s on Linux
function cpuOfTree(pid, { skip = [], withSelf = true } = {}) {
    const children = new Map();
    for (const d of readdirSync('/proc')) {
        if (!/^\d+$/.test(d)) continue;
        try {
            const stat = readFileSync(`/proc/${d}/stat`, 'utf8');
            const f = stat.slice(stat.lastIndexOf(')') + 2).split(' ');
            const ppid = Number(f[1]);
            if (!children.has(ppid)) children.set(ppid, []);
            children.get(ppid).push({ pid: Number(d), cpu: (Number(f[11]) + Number(f[12])) / kTicks });
        } catch { /* the process ended meanwhile */ }
    }
    let total = 0;
    const self = (() => {
        try {
            const stat = readFileSync(`/proc/${pid}/stat`, 'utf8');
            const f = stat.slice(stat.lastIndexOf(')') + 2).split(' ');
            return (Number(f[11]) + Number(f[12])) / kTicks;
        } catch { return 0; }
    })();
    const walk = (p) => {
        for (const c of children.get(p) ?? []) {
            if (skip.includes(c.pid)) continue;
            total += c.cpu;
            walk(c.pid);
        }
    };
    walk(pid);
    return total + (withSelf ? self : 0);
}

const median = (xs) => {
    const s = [...xs].sort((a, b) => a - b);
    return s.length % 2 ? s[(s.length - 1) / 2] : 0.5 * (s[s.length / 2 - 1] + s[s.length / 2]);
};

function summarise(runs) {
    const med = (key) => (runs[0][key] === undefined ? null : median(runs.map((r) => r[key])));
    return {
        first_ms: med('first_ms'),
        first_min_ms: Math.min(...runs.map((r) => r.first_ms)),
        frame_ms: med('frame_ms'),
        frame_min_ms: Math.min(...runs.map((r) => r.frame_ms)),
        work_ms: med('work_ms'),
        main_ms: med('main_ms'),
        bytes: med('bytes'),
        triangles: med('triangles'),
        client_cpu_s: med('client_s'),
        server_cpu_s: med('server_s'),
        runs,
    };
}

async function main() {
    const o = parseArgs(process.argv.slice(2));
    const datasets = [{ name: 'phantom', path: null, iso: 50, more: [60, 70] }];
    if (existsSync(o.head)) datasets.push({ name: 'head', path: o.head, iso: o.headIso, more: [o.headIso + 10, o.headIso + 20] });
    else console.log(`bench_page: ${o.head} is absent; the head is skipped`);
    mkdirSync(o.out, { recursive: true });
    const { chromium } = requireWeb('playwright-core');
    const server = await startServer(o, datasets);
    const browser = await chromium.launch({
        executablePath: '/usr/bin/chromium', headless: true,
        args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
    });
    const results = {};
    try {
        for (const d of datasets) {
            const page = [], auto = [], view = [];
            // One warm-up of each: the server's first request on a dataset pages in its octree.
            await pageRun(browser, server, d, o, 3);
            await pageRun(browser, server, d, o);
            if (o.view) viewRun(server, d, o, o.out);
            for (let i = 0; i < o.runs; ++i) {
                page.push(await pageRun(browser, server, d, o, 3));
                auto.push(await pageRun(browser, server, d, o));
                if (o.view) view.push(viewRun(server, d, o, o.out));
                const v = o.view ? `, view ${view[i].first_ms.toFixed(1)} / ${view[i].frame_ms.toFixed(1)} ms` : '';
                process.stdout.write(`bench_page: ${d.name} run ${i + 1}/${o.runs}: page ` +
                    `${page[i].first_ms.toFixed(1)} / ${page[i].frame_ms.toFixed(1)} ms ` +
                    `(work ${page[i].work_ms.toFixed(1)}), page default ` +
                    `${auto[i].first_ms.toFixed(1)} / ${auto[i].frame_ms.toFixed(1)} ms (work ` +
                    `${auto[i].work_ms.toFixed(1)}, ${auto[i].cells} groups as cells)${v}\n`);
            }
            results[d.name] = {
                iso: d.iso, more: d.more, page: summarise(page), page_auto: summarise(auto),
                page_later: summarise(page.flatMap((r) => r.later)),
                page_auto_later: summarise(auto.flatMap((r) => r.later)),
                ...(o.view ? { view: summarise(view) } : {}),
            };
        }
    } finally {
        await browser.close();
        server.proc.kill('SIGINT');
    }
    const rows = [`| dataset | client | frames | first group ms (median, fastest) | ` +
                  `end of frame ms (median, fastest) | page's work ms | main thread CPU ms | ` +
                  `client CPU s | server CPU s | bytes | triangles | page / view, end of frame |`,
                  '|---|---|---|---|---|---|---|---|---|---|---|---|'];
    const names = { page: 'browser page, compact+zstd, LOD on', page_auto: 'browser page, its defaults',
                    view: 'isowall view' };
    const verdicts = [];
    const ratioText = (x) => `${x.toFixed(2)}x (${x <= 1 ? 'no worse' : 'WORSE'})`;
    const f1 = (x) => (x === null ? '' : x.toFixed(1));
    const f2 = (x) => (x === null ? '' : x.toFixed(2));
    for (const [name, r] of Object.entries(results)) {
        const verdict = (what, a, b) => `${name}, ${what}: the page at its defaults against ` +
            `compact+zstd with LOD on (today's): end of frame ${ratioText(a.frame_ms / b.frame_ms)}, ` +
            `the page's work ${ratioText(a.work_ms / b.work_ms)}, main-thread CPU ` +
            `${ratioText(a.main_ms / b.main_ms)}`;
        verdicts.push(verdict('first frame of a fresh page', r.page_auto, r.page));
        verdicts.push(verdict(`later frames (new isovalues ${r.more.join(', ')})`, r.page_auto_later, r.page_later));
        const shown = [['page', 'first'], ['page_later', 'later'], ['page_auto', 'first'],
                       ['page_auto_later', 'later'], ['view', 'first']];
        for (const [who, frames] of shown) {
            const s = r[who];
            if (!s) continue;
            const client = names[who.replace('_later', '')];
            const vsView = who === 'page' || who === 'page_auto' ? r.view : null;
            rows.push(`| ${name} (iso ${r.iso}) | ${client} | ${frames} | ` +
                `${f1(s.first_ms)}, ${f1(s.first_min_ms)} | ${f1(s.frame_ms)}, ${f1(s.frame_min_ms)} | ` +
                `${f1(s.work_ms)} | ${f1(s.main_ms)} | ${f2(s.client_cpu_s)} | ${f2(s.server_cpu_s)} | ` +
                `${Math.round(s.bytes)} | ${Math.round(s.triangles)} | ` +
                `${vsView ? (s.frame_ms / vsView.frame_ms).toFixed(2) : ''} |`);
        }
    }
    const header = `Front view ${o.size}; today's page and view: case 5 (LOD on, cache, compact + zstd); ` +
                   `fresh connection each run, ` +
                   `${o.runs} runs after one warm-up, loopback, ${new Date().toISOString()}`;
    console.log(`\n${header}\n\n${rows.join('\n')}\n\n${verdicts.join('\n')}`);
    writeFileSync(path.join(o.out, 'bench.json'), JSON.stringify({ size: o.size, runs: o.runs, results }, null, 1));
    writeFileSync(path.join(o.out, 'bench.md'), `${header}\n\n${rows.join('\n')}\n\n${verdicts.join('\n')}\n`);
}

main().catch((e) => fail(e.message));
