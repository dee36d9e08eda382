// Tokenizes every example and every ```bat block of docs/language.md with
// the grammar engine VS Code uses (vscode-textmate + vscode-oniguruma), and
// fails if a line leaves no token, a word is left unscoped, or a comment is
// not scoped as a comment. Run from this folder after `npm install`:
//   node test/tokenize.js
const fs = require("fs");
const path = require("path");
const tm = require("vscode-textmate");
const oniguruma = require("vscode-oniguruma");

const root = path.join(__dirname, "..", "..", "..");
const wasm = fs.readFileSync(require.resolve("vscode-oniguruma/release/onig.wasm")).buffer;

async function main() {
  await oniguruma.loadWASM(wasm);
  const registry = new tm.Registry({
    onigLib: Promise.resolve({
      createOnigScanner: (p) => new oniguruma.OnigScanner(p),
      createOnigString: (s) => new oniguruma.OnigString(s),
    }),
    loadGrammar: async () =>
      tm.parseRawGrammar(
        fs.readFileSync(path.join(__dirname, "..", "syntaxes", "shaping.tmLanguage.json"), "utf8"),
        "shaping.tmLanguage.json"
      ),
  });
  const grammar = await registry.loadGrammar("source.shaping");
  const sources = [];
  for (const f of fs.readdirSync(path.join(root, "examples")).filter((f) => f.endsWith(".bat"))) {
    sources.push([f, fs.readFileSync(path.join(root, "examples", f), "utf8")]);
  }
  const doc = fs.readFileSync(path.join(root, "docs", "language.md"), "utf8");
  const blocks = doc.split("```bat").slice(1).map((b) => b.slice(b.indexOf("\n") + 1, b.indexOf("```")));
  blocks.forEach((b, i) => sources.push([`language.md block ${i + 1}`, b]));
  let failures = 0;
  let tokens = 0;
  let keywords = 0;
  for (const [name, text] of sources) {
    let state = tm.INITIAL;
    text.split("\n").forEach((line, n) => {
      const r = grammar.tokenizeLine(line, state);
      state = r.ruleStack;
      for (const t of r.tokens) {
        tokens++;
        const word = line.slice(t.startIndex, t.endIndex);
        const scopes = t.scopes.join(" ");
        if (/keyword\.declaration/.test(scopes)) keywords++;
        if (/^\s*\/\//.test(word) && !/comment/.test(scopes)) {
          console.error(`${name}:${n + 1}: comment ${JSON.stringify(word)} scoped ${scopes}`);
          failures++;
        }
        if (/[A-Za-z0-9]/.test(word) && t.scopes.length < 2) {
          console.error(`${name}:${n + 1}: ${JSON.stringify(word)} has no scope`);
          failures++;
        }
      }
    });
  }
  console.log(`${sources.length} sources, ${tokens} tokens, ${keywords} declaration keywords`);
  if (failures > 0 || keywords < sources.length) {
    console.error("the TextMate grammar failed on the sources above");
    process.exit(1);
  }
  console.log("the TextMate grammar tokenizes every source");
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});
