// A promise that settles as `executor` says, or rejects after `ms` milliseconds naming `what`: every
// wait of the node clients is bounded, so a test never hangs on a server that stays silent.
export function bounded(what, ms, executor) {
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`${what}: no answer within ${ms} ms`)), ms);
    executor(
      (value) => {
        clearTimeout(timer);
        resolve(value);
      },
      (error) => {
        clearTimeout(timer);
        reject(error);
      },
    );
  });
}
