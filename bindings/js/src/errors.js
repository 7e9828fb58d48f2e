// The rejection of spec/format.md section 9: a category (format, limit,
// invalid_data, numeric) and a reason identifier, the same pair that
// sogmm-inspect prints, plus a sentence for people.
export class SogmmError extends Error {
  constructor(category, reason, message) {
    super(`${reason}: ${message}`);
    this.name = 'SogmmError';
    this.category = category;
    this.reason = reason;
  }
}

export function fail(category, reason, message) {
  throw new SogmmError(category, reason, message);
}

export function formatError(reason, message) {
  fail('format', reason, message);
}
