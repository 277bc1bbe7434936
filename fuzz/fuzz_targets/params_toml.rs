//! The TOML parameter readers on arbitrary text: never panic; accepted rig
//! parameters give a model summary (or a clean error) and survive a TOML
//! round trip; accepted rig effects validate or fail cleanly; an accepted
//! drive structure gives its closed loop (or a clean error) with finite
//! figures.
#![no_main]

use feedid::drive::{D1Variant, DriveStructure, ModelSummary, RigEffects, RigParams};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(p) = RigParams::from_toml_str(text, Some("fuzz.toml".as_ref())) {
        assert!(p.validate().is_ok());
        let k = p.stiffness_k();
        let j = p.inertia_j();
        assert!(k.is_finite() && j.is_finite(), "K {k}, J {j}");
        for v in [D1Variant::Corrected, D1Variant::PaperPrinted] {
            let _ = ModelSummary::new(&p, v);
        }
        let back = RigParams::from_toml_str(&p.to_toml_string(), None);
        assert_eq!(back.ok(), Some(p), "TOML round trip");
    }
    if let Ok(fx) = toml::from_str::<RigEffects>(text) {
        let _ = fx.validate();
    }
    if let Ok(s) = DriveStructure::from_toml_str(text, Some("fuzz.toml".as_ref())) {
        if let Ok(summary) = s.closed_loop() {
            let text = format!("{summary:?}");
            assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
        }
    }
});
