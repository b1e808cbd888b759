// Clayform Studio (docs/studio.md): strokes drawn in the browser, parent surfaces built from
// them, styled by a bound and a target curve and shaped by lattices, live. The kernel runs in
// `clayform studio` behind one WebSocket; every action is an edit of the recipe (with a named
// history there), and what the page shows is evaluated here from the nets the kernel sends.
//
// This file wires the page's modules (docs/studio.md § The page's modules): the shared state in
// store.js, the scene in scene.js, the analysis views in display.js, one module per tool (sketch,
// select, style, lattice and its handles, constraints), the kernel's replies in replies.js.
import '../style.css';
import './studio.css';
import { body } from './ui.js';
import { busy } from './store.js';
import { wireScene } from './scene.js';
import { wireDrafting } from './drafting.js';
import { sketchPlane, snapEnd } from './sketch_geometry.js';
import { wireDisplay } from './display.js';
import { wireHandles } from './handles.js';
import { wireLattice } from './lattice.js';
import { wireStyle } from './style.js';
import { wireConstraints } from './constraints.js';
import { wireCommands } from './commands.js';
import { wireJobs } from './jobs.js';
import { wireInput, setTool } from './input.js';
import { installTestHook } from './test_hook.js';
import { start } from './replies.js';

wireScene();
wireDrafting({ plane: sketchPlane, snap: snapEnd });
wireConstraints();
wireStyle();
wireLattice();
wireHandles();
wireDisplay();
wireCommands();
wireJobs();
wireInput();
setTool('orbit');
installTestHook();
start();
setInterval(() => (body.dataset.busy = busy() ? '1' : '0'), 50);
