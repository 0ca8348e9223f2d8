//! What a soft light's f64 reference reads, from its shade map: CSSM's tables split into the
//! basis and the search's, the integral images and their errors.

use super::*;

/// A CSSM light's shade map (its tables' values side by side, `technique::map_channels`
/// each, as `Frame::shade_maps` holds them) split into the CSM basis (2M channels) and the
/// search's representation (MSM's four quantized moments, or the CSM-Z basis's 2M + 1), padding
/// dropped.
pub fn split_cssm(light: &shadowgraph::Light, map: &Texels) -> (Texels, Texels) {
    let shadowgraph::Technique::Cssm { terms, search, .. } = light.shadow.technique else {
        panic!("not a CSSM light");
    };
    let stored = shadowgraph::low_level::technique::map_channels(light);
    let basis_maps = shadowgraph::low_level::technique::csm_maps(terms) as usize;
    let logical = shadowgraph::low_level::technique::basis_sequence(terms, Some(search));
    // (is a basis table, first stored channel, logical channels) of every table, in binding
    // order.
    let mut first = 0;
    let mut parts = Vec::new();
    for (k, &n) in stored.iter().enumerate() {
        parts.push((k < basis_maps, first, logical[k].1 as usize));
        first += n;
    }
    let pick = |basis: bool| {
        let channels: usize = parts.iter().filter(|p| p.0 == basis).map(|p| p.2).sum();
        let data = map
            .data
            .chunks(map.channels)
            .flat_map(|texel| {
                parts
                    .iter()
                    .filter(|p| p.0 == basis)
                    .flat_map(move |&(_, at, n)| texel[at..at + n].iter().copied())
            })
            .collect();
        Texels {
            width: map.width,
            height: map.height,
            channels,
            data,
        }
    };
    (pick(true), pick(false))
}

/// What a soft light's f64 reference reads, prepared once per light from its shade map (the
/// tables' values side by side, as `Frame::shade_maps` holds them): the integral images (CSSM:
/// the basis, then the search's representation), their errors and the device's sin/cos error. `None` for
/// a light whose technique is not soft.
pub struct SoftInputs {
    light: shadowgraph::Light,
    integrals: Vec<Integral>,
    errors: Vec<TableError>,
    e_trig: f64,
}

impl SoftInputs {
    /// The inputs of `light` (a soft technique, else `None`) from its shade map `level0`.
    pub fn new(light: &shadowgraph::Light, level0: &Texels, e_trig: f64) -> Option<Self> {
        use shadowgraph::Technique;
        let parts = match light.shadow.technique {
            Technique::Cssm { .. } => {
                let (basis, z) = split_cssm(light, level0);
                vec![basis, z]
            }
            Technique::Vssm { .. } | Technique::MsmSoft { .. } => vec![level0.clone()],
            _ => return None,
        };
        let coding = shadowgraph::low_level::technique::sat_coding(light)
            .expect("valid coding")
            .expect("soft techniques read tables");
        Some(Self {
            light: light.clone(),
            errors: parts.iter().map(|t| TableError::new(t, &coding)).collect(),
            integrals: parts
                .iter()
                .map(|t| Integral::new(t).filtered(coding.variant == SatVariant::Float))
                .collect(),
            e_trig,
        })
    }

    fn cssm(&self) -> cpu::vis_cssm::Maps<'_> {
        let shadowgraph::Technique::Cssm { search: kind, .. } = self.light.shadow.technique else {
            panic!("not a CSSM light");
        };
        cpu::vis_cssm::Maps {
            basis: &self.integrals[0],
            search: &self.integrals[1],
            kind,
        }
    }

    /// The f64 visibility at `s` (1 outside the map).
    pub fn reference(&self, l: &LightGpu, s: &LightSample) -> f64 {
        use shadowgraph::Technique;
        if !s.inside {
            return 1.0;
        }
        match self.light.shadow.technique {
            Technique::Cssm { .. } => cpu::vis_cssm::vis_cssm(self.cssm(), l, s),
            Technique::MsmSoft { .. } => cpu::vis_msm_soft::vis_msm_soft(&self.integrals[0], l, s),
            _ => cpu::vis_vssm::vis_vssm(&self.integrals[0], l, s),
        }
    }

    /// The tolerance at `s` for reference value `v` (see [`Chain`]; 0 outside the map).
    pub fn tolerance(&self, l: &LightGpu, s: &LightSample, v: f64) -> Option<f64> {
        use shadowgraph::Technique;
        if !s.inside {
            return Some(0.0);
        }
        let (i, e) = (&self.integrals, &self.errors);
        match self.light.shadow.technique {
            Technique::Cssm { .. } => {
                cssm_tolerance(self.cssm(), (&e[0], &e[1]), self.e_trig, l, s, v)
            }
            Technique::MsmSoft { .. } => msm_soft_tolerance(&i[0], &e[0], l, s, v),
            _ => vssm_tolerance(&i[0], &e[0], l, s, v),
        }
    }
}
