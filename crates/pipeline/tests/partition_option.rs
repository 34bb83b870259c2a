//! The partition method as a mesh option: METIS unless told otherwise.
use parafront_pipeline::{MeshOptions, Partition};

#[test]
fn the_partition_option_reads_from_toml_and_defaults_to_metis() {
    let o: MeshOptions = toml::from_str("parts = 8\npartition = \"rcb\"\n").unwrap();
    assert_eq!(o.partition, Partition::Rcb);
    let o: MeshOptions = toml::from_str("parts = 8\n").unwrap();
    assert_eq!(o.partition, Partition::Metis);
    assert_eq!(MeshOptions::default().partition, Partition::Metis);
    assert!(toml::from_str::<MeshOptions>("partition = \"kway\"\n").is_err());
}
