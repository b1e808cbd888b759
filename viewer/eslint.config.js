// ESLint (flat config, ESLint 9) for the page and its end-to-end tests: the recommended rules,
// browser globals for src/, Node's for the build config, both for e2e/ (Node code that hands
// functions to the page). Run by `scripts/viewer.sh lint`
// and the ctest "house: the page's JavaScript passes ESLint".
import js from "@eslint/js";
import globals from "globals";

export default [
  { ignores: ["dist/", "node_modules/"] },
  js.configs.recommended,
  {
    files: ["src/**/*.js"],
    languageOptions: { ecmaVersion: 2022, sourceType: "module", globals: globals.browser },
  },
  {
    files: ["vite.config.js", "eslint.config.js"],
    languageOptions: { ecmaVersion: 2022, sourceType: "module", globals: globals.node },
  },
  {
    // The tests run in Node and hand functions to the page (page.evaluate), which run there.
    files: ["e2e/**/*.mjs", "e2e/**/*.js"],
    languageOptions: {
      ecmaVersion: 2022,
      sourceType: "module",
      globals: { ...globals.node, ...globals.browser },
    },
  },
];
