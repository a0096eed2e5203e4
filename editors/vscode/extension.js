// The aou extension: starts `aouc server` (the language server of aou) for .aou files.
// Highlighting comes from syntaxes/aou.tmLanguage.json and needs no server.
const vscode = require("vscode");
const { LanguageClient } = require("vscode-languageclient/node");

let client;

function activate(context) {
  const config = vscode.workspace.getConfiguration("aou");
  const [command, ...args] = config.get("server.command", ["aouc", "server"]);
  const robot = config.get("robot", "");
  client = new LanguageClient(
    "aou",
    "aou language server",
    { command, args },
    {
      documentSelector: [{ scheme: "file", language: "aou" }, { scheme: "untitled", language: "aou" }],
      initializationOptions: {
        robot: robot || undefined,
        compileDelay: config.get("compileDelay", 0.8),
      },
    }
  );
  context.subscriptions.push(client);
  return client.start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
