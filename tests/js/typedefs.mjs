// roslibjs, unchanged, asking a running cbrs server how its types are defined, as a page that builds
// forms or decoders from rosapi's typedefs does. tests/test_clients_bridge.py runs it and checks what it
// prints (one line of JSON) against the definitions in cbrs/interfaces.
//
//     node tests/js/typedefs.mjs PORT
//
// Every wait is bounded; the script gives up (exit status 2) after 30 s in all.

import { Ros, Service } from "roslib";
import { bounded } from "./bounded.mjs";

const WAIT = 10000;
setTimeout(() => {
  console.error("typedefs.mjs: gave up after 30 s");
  process.exit(2);
}, 30000).unref();

const ros = await bounded("connect", WAIT, (resolve, reject) => {
  const connection = new Ros({ url: `ws://127.0.0.1:${Number(process.argv[2])}` });
  connection.on("connection", () => resolve(connection));
  connection.on("error", (error) => reject(new Error(`connect: ${error?.message ?? error}`)));
});
const ask = (what, method, type) => bounded(what, WAIT, (resolve, reject) => ros[method](type, resolve, reject));

const found = {};
const request = await ask("request details", "getServiceRequestDetails", "cbrs/Match");
const response = await ask("response details", "getServiceResponseDetails", "cbrs/Match");
const progress = await ask("message details", "getMessageDetails", "cbrs/TaskProgress");
found.request = request.typedefs;
found.response = response.typedefs;
found.progress = progress;
found.decodedRequest = ros.decodeTypeDefs(request.typedefs);
found.decodedResponse = ros.decodeTypeDefs(response.typedefs);
found.decodedProgress = ros.decodeTypeDefs(progress);

// A form filled from the request typedef: every field at its example, the requirement typed in.
const zero = { "": "", 0: 0, "0.0": 0.0, False: false, "[]": [], "{}": {} };
const form = Object.fromEntries(request.typedefs[0].fieldnames.map((name, i) => [name, zero[request.typedefs[0].examples[i]]]));
form.requirement = "RobotSelfPosition";
const service = new Service({ ros, name: "/cbrs/match", serviceType: "cbrs/Match" });
const ranked = await bounded("call /cbrs/match", WAIT, (resolve) =>
  service.callService(form, resolve, (error) => resolve({ failed: String(error) })),
);
found.form = form;
found.ranked = ranked.failed ?? ranked.candidates.length;
console.log(JSON.stringify(found));
ros.close();
process.exit(0);
