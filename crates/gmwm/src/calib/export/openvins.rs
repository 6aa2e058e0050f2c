//! OpenVINS `kalibr_imu_chain.yaml` (docs/methods.md §14.4): the Kalibr keys under `imu0:`.

use super::kalibr::kalibr_like;
use super::{ExportError, ExportFormat, NavNoise, Stack};

/// OpenVINS `kalibr_imu_chain.yaml`.
pub(super) struct OpenVins;

impl Stack for OpenVins {
    fn name(&self) -> &'static str {
        "openvins"
    }
    fn file_name(&self) -> &'static str {
        "kalibr_imu_chain.yaml"
    }
    fn render(&self, noise: &NavNoise) -> Result<String, ExportError> {
        kalibr_like(ExportFormat::OPENVINS, noise)
    }
}
