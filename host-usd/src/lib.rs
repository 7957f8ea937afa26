//! `host-usd`: USD scene import (usda, usdc, usdz) for ppis. Tracked by the host-usd issue;
//! empty until then.
