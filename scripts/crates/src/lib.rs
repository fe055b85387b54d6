// SPDX-License-Identifier: MIT
// Empty: the package exists only so that cargo fetches its dependencies (Cargo.toml).
