// Vite 6 (it runs on Debian 12's Node 18 as well as Node 20+; Vite 7 needs Node >= 20.19).
// `npm run build` writes the static page to dist/ with relative URLs (base './'), so `clayform view`
// can serve it at any path. `npm run dev` serves a run folder under /run/ when CLAYFORM_RUN names one
// (e.g. CLAYFORM_RUN=../out/sail npm run dev), as `clayform view` does.
import { defineConfig } from 'vite';
import { createReadStream, statSync } from 'node:fs';
import { resolve, normalize, sep, extname, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));

const TYPES = { '.json': 'application/json', '.bin': 'application/octet-stream' };

function serveRun() {
  const root = process.env.CLAYFORM_RUN ? resolve(process.env.CLAYFORM_RUN) : null;
  return {
    name: 'clayform-run-folder',
    configureServer(server) {
      if (!root) return;
      server.middlewares.use('/run', (req, res, next) => {
        const path = normalize(resolve(root, '.' + decodeURIComponent(req.url.split('?')[0])));
        if (!(path + sep).startsWith(root + sep) && path !== root) return next();
        try {
          if (!statSync(path).isFile()) return next();
        } catch {
          return next();
        }
        res.setHeader('Content-Type', TYPES[extname(path)] || 'application/octet-stream');
        createReadStream(path).pipe(res);
      });
    },
  };
}

export default defineConfig({
  base: './',
  plugins: [serveRun()],
  build: {
    // two pages: the viewer (index.html, clayform view) and the studio (studio.html, clayform studio)
    rollupOptions: { input: { index: resolve(here, 'index.html'), studio: resolve(here, 'studio.html') } },
    outDir: 'dist',
    emptyOutDir: true,
    target: 'es2020',
    chunkSizeWarningLimit: 800,
  },
});
