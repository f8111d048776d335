//! The integration tests of kinpost-toolpath (`cargo test -p kinpost-toolpath --test all`).

mod paths;
