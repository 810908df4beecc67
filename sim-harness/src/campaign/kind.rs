//! What kind of mission a campaign draws: its model, objective and features, and the
//! filters that narrow a campaign to some kinds.

use serde::{Deserialize, Serialize};

/// The vehicle models a mission can use, by their scenario-file names.
pub const MODELS: [&str; 2] = ["2d", "3d"];
/// The objectives, by their scenario-file names.
pub const OBJECTIVES: [&str; 3] = ["fixed-time", "min-time", "min-time-rendezvous"];

/// A feature a mission may have beyond its model and objective.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Feature {
    /// A target sits inside defended airspace: the flown path must cross a threat.
    Unavoidable,
    /// Threats moving along known roads.
    Moving,
    /// Static threats that pop up in flight.
    Popups,
    /// The lead changes its route in flight (rendezvous missions only).
    LeadChange,
    /// A steady wind, with light gusts or none, and an aircraft that lags its commands
    /// and navigates with errors (the harness's truth model).
    Wind,
}

impl Feature {
    /// Every feature, in the order of the report's tables.
    pub const ALL: [Feature; 5] = [
        Feature::Unavoidable,
        Feature::Moving,
        Feature::Popups,
        Feature::LeadChange,
        Feature::Wind,
    ];

    /// The name used on the command line and in the results.
    pub fn name(self) -> &'static str {
        match self {
            Feature::Unavoidable => "unavoidable",
            Feature::Moving => "moving",
            Feature::Popups => "popups",
            Feature::LeadChange => "lead-change",
            Feature::Wind => "wind",
        }
    }

    /// The feature named `s` (as [`Feature::name`] writes it).
    pub fn parse(s: &str) -> Result<Feature, String> {
        Feature::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Feature::ALL.iter().map(|f| f.name()).collect();
                format!("unknown feature `{s}` (one of {})", names.join(", "))
            })
    }
}

/// What one mission is: the draw's choices and what the layout came out with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MissionKind {
    pub model: String,
    pub objective: String,
    pub targets: usize,
    /// Static threats known before take-off.
    pub threats: usize,
    pub popups: usize,
    pub moving: usize,
    pub unavoidable: bool,
    pub lead_change: bool,
    /// Flown in a wind (told to the planner) by the harness's truth model.
    #[serde(default)]
    pub wind: bool,
    /// The defended threat an unavoidable layout's target sits in (the one threat its
    /// flight may enter).
    #[serde(default)]
    pub defended: Option<String>,
}

impl MissionKind {
    /// Whether the mission has feature `f`.
    pub fn has(&self, f: Feature) -> bool {
        match f {
            Feature::Unavoidable => self.unavoidable,
            Feature::Moving => self.moving > 0,
            Feature::Popups => self.popups > 0,
            Feature::LeadChange => self.lead_change,
            Feature::Wind => self.wind,
        }
    }

    /// One line for people: `3d min-time, 2 targets, 9 threats, avoidable, 1 pop-up`.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "{} {}, {} target(s), {} threat(s), {}",
            self.model,
            self.objective,
            self.targets,
            self.threats,
            if self.unavoidable {
                "unavoidable"
            } else {
                "avoidable"
            }
        );
        if self.moving > 0 {
            s.push_str(&format!(", {} moving", self.moving));
        }
        if self.popups > 0 {
            s.push_str(&format!(", {} pop-up(s)", self.popups));
        }
        if self.lead_change {
            s.push_str(", lead changes route");
        }
        if self.wind {
            s.push_str(", wind");
        }
        s
    }
}

/// Which missions a campaign draws. Empty lists allow everything; a mission drawn under a
/// filter draws only among the allowed choices (so `--model 2d` gives 2-D missions, not
/// fewer missions).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Filter {
    /// Allowed models (`2d`, `3d`); empty: both.
    pub models: Vec<String>,
    /// Allowed objectives; empty: all three.
    pub objectives: Vec<String>,
    /// Every mission has these features.
    pub with: Vec<Feature>,
    /// No mission has these.
    pub without: Vec<Feature>,
}

impl Filter {
    /// Checks the names and that some mission can pass the filter.
    pub fn validate(&self) -> Result<(), String> {
        for m in &self.models {
            if !MODELS.contains(&m.as_str()) {
                return Err(format!("unknown model `{m}` (2d or 3d)"));
            }
        }
        for o in &self.objectives {
            if !OBJECTIVES.contains(&o.as_str()) {
                return Err(format!(
                    "unknown objective `{o}` (one of {})",
                    OBJECTIVES.join(", ")
                ));
            }
        }
        if let Some(f) = self.with.iter().find(|f| self.without.contains(f)) {
            return Err(format!("feature `{}` both required and excluded", f.name()));
        }
        if self.with.contains(&Feature::LeadChange)
            && !self.objectives().contains(&"min-time-rendezvous")
        {
            return Err("`lead-change` needs the min-time-rendezvous objective".into());
        }
        Ok(())
    }

    /// The models a mission may draw.
    pub fn models(&self) -> Vec<&'static str> {
        allowed(&MODELS, &self.models)
    }

    /// The objectives a mission may draw (only the rendezvous when a lead change is
    /// required).
    pub fn objectives(&self) -> Vec<&'static str> {
        let all = allowed(&OBJECTIVES, &self.objectives);
        if self.with.contains(&Feature::LeadChange) {
            all.into_iter()
                .filter(|o| *o == "min-time-rendezvous")
                .collect()
        } else {
            all
        }
    }

    /// Whether feature `f` is drawn with probability `p`, forced on, or forced off.
    pub fn chance(&self, f: Feature, p: f64) -> f64 {
        if self.with.contains(&f) {
            1.0
        } else if self.without.contains(&f) {
            0.0
        } else {
            p
        }
    }

    /// The filter as command-line flags (empty when it allows everything).
    pub fn flags(&self) -> String {
        let mut s = Vec::new();
        for m in &self.models {
            s.push(format!("--model {m}"));
        }
        for o in &self.objectives {
            s.push(format!("--objective {o}"));
        }
        for f in &self.with {
            s.push(format!("--with {}", f.name()));
        }
        for f in &self.without {
            s.push(format!("--without {}", f.name()));
        }
        s.join(" ")
    }
}

fn allowed(all: &[&'static str], chosen: &[String]) -> Vec<&'static str> {
    all.iter()
        .copied()
        .filter(|a| chosen.is_empty() || chosen.iter().any(|c| c == a))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filters_check_their_names_and_conflicts() {
        let mut f = Filter::default();
        assert!(f.validate().is_ok());
        assert_eq!(f.models(), vec!["2d", "3d"]);
        f.models = vec!["4d".into()];
        assert!(f.validate().unwrap_err().contains("4d"));
        f.models = vec!["3d".into()];
        f.with = vec![Feature::LeadChange];
        assert_eq!(f.objectives(), vec!["min-time-rendezvous"]);
        f.objectives = vec!["min-time".into()];
        assert!(f.validate().unwrap_err().contains("rendezvous"));
        f.objectives.clear();
        f.without = vec![Feature::LeadChange];
        assert!(f.validate().unwrap_err().contains("both"));
        assert!(Feature::parse("pop-ups").is_err());
        assert_eq!(Feature::parse("popups"), Ok(Feature::Popups));
        assert_eq!(Feature::parse("wind"), Ok(Feature::Wind));
    }
}
