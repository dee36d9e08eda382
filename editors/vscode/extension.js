// Starts `shaping lsp` for files of the `shaping` language.
const vscode = require("vscode");
const { LanguageClient } = require("vscode-languageclient/node");

let client;

function activate(context) {
  const command = vscode.workspace.getConfiguration("shaping").get("server.path", "shaping");
  const server = { command, args: ["lsp"] };
  client = new LanguageClient(
    "shaping",
    "shaping language server",
    { run: server, debug: server },
    { documentSelector: [{ language: "shaping" }] }
  );
  context.subscriptions.push(client);
  return client.start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
