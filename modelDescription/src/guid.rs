//! A GUID derived from the content, so that equal descriptions get equal GUIDs.

use sha2::{Digest, Sha256};

use crate::types::ModelDescription;

impl ModelDescription {
    /// SHA-256 of [`ModelDescription::to_xml`] of a copy whose `guid` is empty, as
    /// `{xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx}` (first 16 bytes, lowercase hex). Changes
    /// whenever anything written to the XML changes; independent of the current `guid`.
    pub fn content_guid(&self) -> String {
        let mut copy = self.clone();
        copy.guid = String::new();
        let digest = Sha256::digest(copy.to_xml().as_bytes());
        let hex: String = digest.iter().take(16).map(|b| format!("{b:02x}")).collect();
        format!("{{{}-{}-{}-{}-{}}}", &hex[0..8], &hex[8..12], &hex[12..16], &hex[16..20], &hex[20..32])
    }

    /// Sets `guid` to [`ModelDescription::content_guid`].
    pub fn with_content_guid(mut self) -> Self {
        self.guid = self.content_guid();
        self
    }
}
