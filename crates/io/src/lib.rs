//! Writers and volume-mesh readers.
